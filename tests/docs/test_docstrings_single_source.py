"""The docstrings of ``vereshchagin._core`` are written once, in ``vereshchagin/_docstrings.py``.

Every bound class, method, property and function of the compiled module carries exactly
``DOCS[key]`` (behind pybind11's generated signature line), every ``DOCS`` entry is used, and no
docstring is left as a string literal in the C++ bindings (``python/bindings``).
"""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import pytest

import vereshchagin._core as core
from vereshchagin._docstrings import DOCS

# The source tree's bindings, wherever below the root this file lives.
BINDINGS = next(
    p / "python" / "bindings" for p in Path(__file__).resolve().parents if (p / "python" / "bindings").is_dir()
)

# Keys are the Python-visible dotted names in _core ("Chain.fk", "Tree.mass_matrix"); the module,
# its private functions and the C++ core of the Python Solver class (vereshchagin.Solver is the
# wrapper in solver.py) carry a "_core." prefix.
_PREFIXED = ("Solver",)

# Attributes every class has (not bound by the bindings).
_CLASS_ATTRIBUTES = {"__doc__", "__module__", "__dict__", "__weakref__", "__qualname__", "__annotations__"}


def _key(dotted: str) -> str:
    if dotted == "_core" or dotted.startswith("_") or dotted.split(".")[0] in _PREFIXED:
        return dotted if dotted == "_core" else "_core." + dotted
    return dotted


def _function_of(obj):
    """The builtin function behind a bound method, static method or module function, else None."""
    raw = obj.__func__ if isinstance(obj, staticmethod) or type(obj).__name__ == "instancemethod" else obj
    return raw if type(raw).__name__ == "builtin_function_or_method" else None


def _is_pybind11_function(obj) -> bool:
    """pybind11 functions are builtins whose self is their function record (pybind11's own type)."""
    func = _function_of(obj)
    return func is not None and "function_record" in type(getattr(func, "__self__", None)).__name__.lower()


def _bound_objects():
    """(dotted name, object) of the module, its functions and classes and their members, as bound in
    C++ (Python functions attached later, e.g. Chain.from_kdl, and CPython's slot wrappers left out)."""
    yield "_core", core
    for name, obj in vars(core).items():
        if name.startswith("__") or inspect.ismodule(obj):
            continue
        if not inspect.isclass(obj):
            if callable(obj):
                yield name, obj
            continue
        if getattr(obj, "__module__", "") != core.__name__ or issubclass(obj, BaseException):
            continue  # SolverError: pybind11's register_exception, no docstring of its own
        yield name, obj
        for mname, member in vars(obj).items():
            raw = member.__func__ if isinstance(member, staticmethod) else member
            if mname in _CLASS_ATTRIBUTES or inspect.isfunction(raw) or type(raw).__name__ == "wrapper_descriptor":
                continue
            yield f"{name}.{mname}", member


def _user_doc(name: str, obj) -> str:
    """The docstring without pybind11's generated 'name(self: T, ...) -> R' header."""
    if not _is_pybind11_function(obj):
        return obj.__doc__ or ""
    doc = _function_of(obj).__doc__ or ""  # a staticmethod object has a __doc__ of its own
    if not doc:
        return ""  # pybind11's _pybind11_conduit_v1_
    first, _, rest = doc.partition("\n")
    assert re.fullmatch(rf"{re.escape(name)}\(.*\)( -> .+)?", first), f"{name}: no pybind11 signature: {first!r}"
    if not rest:
        return ""
    assert rest.startswith("\n") and rest.endswith("\n"), f"{name}: unexpected layout {doc!r}"
    return rest[1:-1]


def _expected(text: str) -> str:
    """DOCS text as __doc__ shows it: CPython moves a 'name(...)\\n--\\n\\n' header to __text_signature__."""
    return re.sub(r"\A\w+\(.*\)\n--\n\n", "", text)


BOUND = dict(_bound_objects())


def test_the_walk_finds_the_bound_api():
    assert len(BOUND) > 100, len(BOUND)
    for name in ("Chain.fk", "Tree.mass_matrix", "Solver.n_joints", "SolveResult.qdd", "Joint.revolute"):
        assert name in BOUND, name


@pytest.mark.parametrize("name", sorted(BOUND))
def test_bound_docstring_is_the_docs_entry(name):
    obj = BOUND[name]
    doc = _user_doc(name.split(".")[-1], obj)
    key = _key(name)
    if key not in DOCS:
        assert not doc, f"{name} has a docstring that is not DOCS[{key!r}]: {doc[:200]!r}"
        return
    assert doc == _expected(DOCS[key]), f"{name}: __doc__ differs from DOCS[{key!r}]"


def test_every_docs_entry_is_used():
    used = {_key(name) for name in BOUND}
    unused = sorted(set(DOCS) - used)
    assert not unused, f"DOCS entries that no bound object carries: {unused}"


def test_solve_keeps_its_text_signature():
    text = DOCS["_core.Solver.solve"]
    assert core.Solver.solve.__text_signature__ == text.split("\n", 1)[0][len("solve") :]


# ---- no docstring literal in the C++ bindings ----

_TOKEN = re.compile(
    r"""(?P<raw>R"(?P<delim>[^()\\\s]{0,16})\((?s:.*?)\)(?P=delim)")"""
    r"""|(?P<str>"(?:\\.|[^"\\\n])*")"""
    r"""|(?P<chr>'(?:\\.|[^'\\\n])+')"""
    r"""|(?P<comment>//[^\n]*|/\*(?s:.*?)\*/)"""
    r"""|(?P<id>[A-Za-z_]\w*)"""
    r"""|(?P<ws>\s+)"""
    r"""|(?P<op>::|.)"""
)


def _tokens(source: str):
    """(kind, text) of C++ tokens: 'str' for string literals (raw ones too), 'id', 'op'; comments,
    character literals and white space dropped."""
    out = []
    for m in _TOKEN.finditer(source):
        kind = m.lastgroup if m.lastgroup != "delim" else "raw"
        if kind in ("comment", "ws", "chr"):
            continue
        out.append(("str" if kind == "raw" else kind, m.group(0)))
    return out


def _closing(tokens, start):
    """Index of the bracket closing tokens[start] ('(' or '{')."""
    pairs = {"(": ")", "{": "}", "[": "]"}
    depth = 0
    for k in range(start, len(tokens)):
        text = tokens[k][1]
        if text in pairs:
            depth += 1
        elif text in pairs.values():
            depth -= 1
            if depth == 0:
                return k
    raise AssertionError("unbalanced brackets")


_BINDERS = {"def", "def_static", "def_property", "def_property_readonly", "def_readonly", "def_readwrite", "class_"}
_C_TABLES = {"PyMethodDef", "PyGetSetDef", "PyMemberDef", "PyType_Slot"}


def _docstring_literals(path: Path):
    """(line, literal) of string literals in documentation positions: after the name among a
    pybind11 binder's direct arguments (a default value such as py::arg("x") = "a" excepted),
    after the name in an entry of a C method, getset, member or slot table, and as mod.doc()."""
    source = path.read_text()
    tokens = _tokens(source)
    found = []

    def line_of(tok_text):
        return source[: source.find(tok_text)].count("\n") + 1

    for k, (kind, text) in enumerate(tokens):
        if kind == "id" and text in _BINDERS:
            j = k + 1
            if j < len(tokens) and tokens[j][1] == "<":  # class_<T> [name](...)
                depth = 0
                while j < len(tokens):
                    depth += {"<": 1, ">": -1}.get(tokens[j][1], 0)
                    j += 1
                    if depth == 0:
                        break
                if j < len(tokens) and tokens[j][0] == "id":
                    j += 1
            if j >= len(tokens) or tokens[j][1] != "(":
                continue
            end = _closing(tokens, j)
            depth, literals = 0, []
            for i in range(j + 1, end):
                t_kind, t_text = tokens[i]
                if t_text in "({[":
                    depth += 1
                elif t_text in ")}]":
                    depth -= 1
                elif t_kind == "str" and depth == 0 and tokens[i - 1][1] != "=":
                    literals.append(t_text)
            # The first is the bound name; the pieces of a concatenated docstring ("a" "b") count one by one.
            found += [(line_of(lit), lit) for lit in literals[1:]]
        elif kind == "id" and text in _C_TABLES:
            j = k + 1
            while j < len(tokens) and tokens[j][1] not in ("=", ";", "("):
                j += 1
            if j + 1 >= len(tokens) or tokens[j][1] != "=" or tokens[j + 1][1] != "{":
                continue
            end = _closing(tokens, j + 1)
            entry = []
            for i in range(j + 1, end + 1):
                if tokens[i][1] == "{":
                    entry = []
                elif tokens[i][0] == "str":
                    entry.append(tokens[i][1])
                elif tokens[i][1] == "}" and len(entry) > 1:
                    found += [(line_of(lit), lit) for lit in entry[1:]]
        elif text == "doc" and tokens[k + 1 : k + 4] == [("op", "("), ("op", ")"), ("op", "=")]:
            if tokens[k + 4][0] == "str":
                found.append((line_of(tokens[k + 4][1]), tokens[k + 4][1]))
    return found


def test_the_literal_check_sees_docstrings(tmp_path):
    fake = tmp_path / "fake_bindings.cpp"
    fake.write_text(
        'cls.def("fk", &fk, py::arg("q"), py::arg("s") = "tip", "Pose of a frame.");\n'
        'py::class_<T> cls(mod, "T", R"doc(A class.)doc");\n'
        'PyMethodDef m[] = {{"f", f, METH_O, "Does f."}, {nullptr, nullptr, 0, nullptr}};\n'
        'mod.doc() = "The module.";\n'
        'cls.def("g", &g, py::arg("x") = "default", doc("T.g"));\n'
    )
    literals = [lit for _, lit in _docstring_literals(fake)]
    assert literals == ['"Pose of a frame."', 'R"doc(A class.)doc"', '"Does f."', '"The module."']


# A docstring kept in a C++ constant or returned by a C++ function would escape the check above:
# a long literal that initialises a constant or is returned must be an error message, i.e. the
# constant is passed to raise(...).
_LONG = 60


def _statements(tokens):
    """Token lists split at ';', '{' and '}'."""
    current = []
    for tok in tokens:
        if tok[1] in (";", "{", "}"):
            if current:
                yield current
            current = []
        else:
            current.append(tok)
    if current:
        yield current


def _long_literals_outside_messages(paths):
    per_file = {path: _tokens(path.read_text()) for path in paths}
    raised = set()  # constants passed to raise(...)
    for tokens in per_file.values():
        for k in range(len(tokens) - 3):
            if tokens[k][1] == "raise" and tokens[k + 1][1] == "(" and tokens[k + 3][1] == ")":
                raised.add(tokens[k + 2][1])
    found = []
    for path, tokens in per_file.items():
        for stmt in _statements(tokens):
            texts = [text for _, text in stmt]
            if "=" in texts and "(" not in texts[: texts.index("=")]:  # a declaration or assignment
                if texts[texts.index("=") - 1] in raised:
                    continue
                value = stmt[texts.index("=") + 1 :]
            elif texts[0] == "return":
                value = stmt[1:]
            else:
                continue
            run = ""
            for kind, text in value + [("op", "")]:
                if kind == "str":
                    run += text
                    continue
                if len(run) > _LONG:
                    found.append((path.name, run[:80]))
                run = ""
    return found


def test_no_docstring_constant_in_the_bindings():
    paths = sorted(BINDINGS.glob("*.[ch]pp"))
    assert len(paths) > 10
    found = _long_literals_outside_messages(paths)
    assert not found, f"long literals in constants or return values (docstrings belong in _docstrings.py): {found}"


def test_the_long_literal_check_sees_a_docstring_constant(tmp_path):
    fake = tmp_path / "fake.cpp"
    fake.write_text(
        'const char* kFkDoc = "Pose of a frame in the base frame, as a homogeneous transform (m).";\n'
        'const char* kMessage = "a long message of an error that raise(kMessage) hands to Python.";\n'
        'void f() { if (bad) raise(kMessage); if (worse) raise("a long message of an error raised in place, '
        'with more words"); }\n'
        'std::string g() { return "Velocity of a frame: linear and angular, base-frame axes (m/s, rad/s)."; }\n'
    )
    found = _long_literals_outside_messages([fake])
    assert [text for _, text in found] == [
        '"Pose of a frame in the base frame, as a homogeneous transform (m)."',
        '"Velocity of a frame: linear and angular, base-frame axes (m/s, rad/s)."',
    ]


@pytest.mark.parametrize("path", sorted(BINDINGS.glob("*.[ch]pp")), ids=lambda p: p.name)
def test_no_docstring_literal_in_the_bindings(path):
    source = path.read_text()
    assert 'R"doc(' not in source, f"{path.name}: a raw docstring literal; move it to _docstrings.py"
    literals = _docstring_literals(path)
    assert not literals, f"{path.name}: docstring literals (use doc(key), _docstrings.py): {literals}"
