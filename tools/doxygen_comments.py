"""Turn the plain ``//`` comments of the public C++ headers into Doxygen comments.

Usage: ``python tools/doxygen_comments.py [HEADER ...]`` (default: every
``cpp/include/vereshchagin/*.hpp``). Rewrites the files in place and prints the ones it changed.
Only the comment markers change, never a comment's text or any code, and a second run changes
nothing, so the script can be rerun after new headers or merges:

* the comment block at the top of a header (before its first line of code) becomes its file
  documentation: ``/// @file`` followed by the block, each ``//`` turned into ``///``;
* a comment block directly above a declaration (no blank line between them) becomes ``///``;
* a comment after a member or an enumerator on the same line becomes ``///<``, and so do the
  comment-only lines below it that continue it (their ``//`` in the same column);
* left alone: comments inside function bodies, in ``private:`` sections, on preprocessor lines, on
  closing braces (``}  // namespace ...``), blocks followed by a blank line, and comments that
  are already Doxygen comments (``///``, ``//!``, ``/** */``).

The docs build (docs/conf.py) runs Doxygen on these headers and fails on its warnings, e.g. a
public member without a comment.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HEADERS = ROOT / "cpp" / "include" / "vereshchagin"

_COMMENT_LINE = re.compile(r"^(\s*)//(?![/!])(.*)$")  # a plain // comment line, not /// or //!
_SCOPE = re.compile(r"\b(namespace|class|struct|union|enum)\b")
_ACCESS = re.compile(r"^\s*(public|protected|private)\s*:")


def _code_part(line: str) -> tuple[str, int]:
    """The line without its trailing plain ``//`` comment, and that comment's column (-1: none).

    String and character literals are skipped, so ``"//"`` inside them is no comment."""
    quote = None
    k = 0
    while k < len(line):
        c = line[k]
        if quote:
            if c == "\\":
                k += 2
                continue
            if c == quote:
                quote = None
        elif c in "\"'":
            quote = c
        elif line.startswith("//", k):
            return line[:k], k
        k += 1
    return line, -1


def _is_plain_comment(comment: str) -> bool:
    """``// text`` (True) versus a Doxygen ``///``, ``//!`` or ``///<`` (False)."""
    return not comment.startswith(("///", "//!"))


class _Scopes:
    """Brace nesting: which braces are namespaces, classes (with their current access) or bodies."""

    def __init__(self):
        self.stack: list[list[str]] = []  # [kind, access]; kind: namespace, class, enum, body
        self.pending = ""  # the code since the last ';', '{' or '}' (the head of the next scope)

    def in_body(self) -> bool:
        return any(kind == "body" for kind, _ in self.stack)

    def hidden(self) -> bool:
        """In a function body, or in a class's private section."""
        if self.in_body():
            return True
        return bool(self.stack) and self.stack[-1][0] == "class" and self.stack[-1][1] == "private"

    def in_enum(self) -> bool:
        return bool(self.stack) and self.stack[-1][0] == "enum"

    def feed(self, code: str) -> None:
        access = _ACCESS.match(code)
        if access and self.stack and self.stack[-1][0] == "class":
            self.stack[-1][1] = access.group(1)
            code = code[access.end() :]
        for c in code:
            if c == "{":
                head = _SCOPE.search(self.pending)
                kind = head.group(1) if head and "(" not in self.pending[: head.start()] else "body"
                if kind in ("class", "struct", "union"):
                    self.stack.append(["class", "private" if kind == "class" else "public"])
                elif kind in ("namespace", "enum"):
                    self.stack.append([kind, ""])
                else:
                    self.stack.append(["body", ""])
                self.pending = ""
            elif c == "}":
                if self.stack:
                    self.stack.pop()
                self.pending = ""
            elif c == ";":
                self.pending = ""
            else:
                self.pending += c
        self.pending += " "


def _doc_line(line: str, marker: str = "///") -> str:
    indent, text = _COMMENT_LINE.match(line).groups()
    return f"{indent}{marker}{text}"


def convert(text: str) -> str:
    """The header ``text`` with Doxygen comment markers (see the module docstring)."""
    lines = text.split("\n")
    out = list(lines)
    # The file comment: the leading block of plain // lines, if the file has no @file yet.
    k = 0
    while k < len(lines) and _COMMENT_LINE.match(lines[k]):
        k += 1
    head_end = k
    if head_end and "@file" not in text and "\\file" not in text:
        out[:head_end] = ["/// @file"] + [_doc_line(line) for line in lines[:head_end]]
    shift = len(out) - len(lines)

    scopes = _Scopes()
    trailing_column = -1  # column of the ///< comment the next comment-only line may continue
    block: list[int] = []  # indices of the plain comment lines above the current line
    for i in range(head_end, len(lines)):
        line = lines[i]
        stripped = line.strip()
        comment_only = _COMMENT_LINE.match(line)
        if comment_only or stripped.startswith("///") or stripped.startswith("//!"):
            column = line.index("//")
            if comment_only and trailing_column == column and not scopes.hidden():
                out[i + shift] = _doc_line(line, "///<")
                continue
            trailing_column = -1
            if comment_only:
                block.append(i)
            else:
                block = []
            continue
        trailing_column = -1
        if not stripped:
            block = []
            continue
        code, column = _code_part(line)
        code_stripped = code.strip()
        declaration = not (code_stripped.startswith(("#", "}")) or _ACCESS.match(code))
        if block and declaration and not scopes.hidden():
            for j in block:
                out[j + shift] = _doc_line(lines[j])
        block = []
        hidden_before = scopes.hidden()
        enum_before = scopes.in_enum()
        scopes.feed(code)
        if column >= 0 and _is_plain_comment(line[column:]) and not hidden_before and not scopes.in_body():
            ends_member = code_stripped.endswith((";", ","))
            enumerator = enum_before and re.fullmatch(r"\w+(\s*=\s*[^{};]*)?", code_stripped) is not None
            if (ends_member or enumerator) and not code_stripped.startswith(("#", "}")):
                out[i + shift] = code + "///<" + line[column + 2 :]
                trailing_column = column
    return "\n".join(out)


def main(argv: list[str]) -> int:
    paths = [Path(a) for a in argv] or sorted(HEADERS.glob("*.hpp"))
    for path in paths:
        text = path.read_text(encoding="utf-8")
        new = convert(text)
        if new != text:
            path.write_text(new, encoding="utf-8")
            print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
