"""The end of a Python benchmark's main: its Markdown report printed, and written to ``--out``."""

from __future__ import annotations

from pathlib import Path


def publish(text: str, out: str | Path | None) -> None:
    """Print a benchmark's report and write it to ``out`` too.

    Parameters
    ----------
    text : str
        The report (Markdown), printed as it is.
    out : str or Path or None
        The ``--out`` file, written in UTF-8; None or "" writes none.
    """
    print(text)
    if out:
        Path(out).write_text(text, encoding="utf-8")
