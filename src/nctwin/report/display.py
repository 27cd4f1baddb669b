"""Tables shown in a chapter: plain text for ``print()`` and nbval, HTML for the book.

A chapter shows each result once, :func:`show` (a paper's table: :func:`show_paper`): one output
that carries the HTML the book renders (:func:`nctwin.report.html.html_table`) and the plain text
a reader of the executed notebook sees (:func:`format_table`, :func:`format_paper_table`). nbval
compares both in the cells it checks, so both are deterministic: the same frame always gives the
same text.
"""

from __future__ import annotations

import pandas as pd

from .html import html_table
from .papers import CITING_COLUMNS
from .results import FLOAT_FORMAT

__all__ = ["format_paper_table", "format_table", "show", "show_paper"]


def _format_float(value: float) -> str:
    return FLOAT_FORMAT % value


def format_table(df: pd.DataFrame) -> str:
    """Render a table as deterministic plain text for ``print()`` in notebooks.

    Floats use :data:`~nctwin.report.results.FLOAT_FORMAT`, missing values print as ``-``, no
    index, every column and row shown, no line wrapping: the same frame always gives the same
    text, so nbval can compare it bit for bit.
    """
    if df.empty and len(df.columns) == 0:
        return "(empty table)"
    return df.to_string(
        index=False, na_rep="-", float_format=_format_float, max_rows=None, max_cols=None
    )


def _paper_parts(df: pd.DataFrame, name: str | None) -> tuple[list[str], pd.DataFrame, list[str]]:
    """Title parts, body and footnotes of a paper table (:func:`format_paper_table`)."""
    body = df.copy()
    title = [name] if name else []
    for column in CITING_COLUMNS:
        if column in body.columns and body[column].nunique(dropna=False) == 1:
            title.append(str(body[column].iloc[0]))
            body = body.drop(columns=column)
    footnotes: list[str] = []
    if "note" in body.columns:
        refs = []
        for note in body["note"]:
            if isinstance(note, str) and note.strip():
                if note not in footnotes:
                    footnotes.append(note)
                refs.append(f"[{footnotes.index(note) + 1}]")
            else:
                refs.append("")
        body = body.drop(columns="note")
        if footnotes:
            body["note"] = refs
    return title, body, footnotes


def format_paper_table(df: pd.DataFrame, name: str | None = None) -> str:
    """Render a paper table with its citation as a title and its notes as footnotes.

    The ``paper`` column and, when constant, ``table`` and ``page_or_section`` go into the title;
    the ``note`` column becomes numbered footnotes (``[1]`` ...) referenced from a ``note``
    column of numbers.

    Parameters
    ----------
    df
        Paper table from :func:`~nctwin.report.papers.load_paper_table`.
    name
        Table name to show in the title, e.g. ``"chien2023_table1"``.
    """
    title, body, footnotes = _paper_parts(df, name)
    lines = [" | ".join(title), format_table(body)] if title else [format_table(body)]
    lines += [f"[{i}] {text}" for i, text in enumerate(footnotes, start=1)]
    return "\n".join(lines)


def show(df: pd.DataFrame, *, digits: int = 4) -> None:
    """Display a table once: compact HTML in the book, :func:`format_table` text beside it.

    One display object carries both forms: ``text/html`` (:func:`nctwin.report.html.html_table`,
    floats to ``digits`` significant digits, the paper's columns grouped), which the book
    renders, and ``text/plain``, exactly the text ``print(format_table(df))`` prints (without
    its final newline); nbval compares both. A chapter cell calls ``show(table)`` where it
    printed ``format_table(table)`` and displayed the frame.
    """
    from IPython.display import display

    display({"text/plain": format_table(df), "text/html": html_table(df, digits=digits)}, raw=True)


def show_paper(df: pd.DataFrame, name: str | None = None) -> None:
    """Display a paper table once: the citation as caption, the notes as footnotes.

    ``text/plain`` is :func:`format_paper_table`; the HTML shows the numbers with six
    significant digits, as the CSV holds them.
    """
    from IPython.display import display

    title, body, footnotes = _paper_parts(df, name)
    page = html_table(body, digits=6, prefix="", caption=" | ".join(title), notes=footnotes)
    display({"text/plain": format_paper_table(df, name), "text/html": page}, raw=True)
