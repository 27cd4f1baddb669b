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


def _footnoted(body: pd.DataFrame, column: str) -> tuple[pd.DataFrame, list[str]]:
    """``body`` with the texts of ``column`` replaced by numbered references (``[1]`` ...; the
    column dropped where no row has a text) and the texts, each once, in order."""
    if column not in body.columns:
        return body, []
    footnotes: list[str] = []
    refs = []
    for note in body[column]:
        if isinstance(note, str) and note.strip():
            if note not in footnotes:
                footnotes.append(note)
            refs.append(f"[{footnotes.index(note) + 1}]")
        else:
            refs.append("")
    body = body.drop(columns=column)
    if footnotes:
        body[column] = refs
    return body, footnotes


def _with_footnotes(text: str, footnotes: list[str]) -> str:
    return "\n".join([text] + [f"[{i}] {note}" for i, note in enumerate(footnotes, start=1)])


def _paper_parts(df: pd.DataFrame, name: str | None) -> tuple[list[str], pd.DataFrame, list[str]]:
    """Title parts, body and footnotes of a paper table (:func:`format_paper_table`)."""
    body = df.copy()
    title = [name] if name else []
    for column in CITING_COLUMNS:
        if column in body.columns and body[column].nunique(dropna=False) == 1:
            title.append(str(body[column].iloc[0]))
            body = body.drop(columns=column)
    body, footnotes = _footnoted(body, "note")
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
    return _with_footnotes("\n".join(lines), footnotes)


def show(
    df: pd.DataFrame,
    *,
    digits: int = 4,
    notes: str | None = None,
    transpose: bool | None = None,
) -> None:
    """Display a table once: compact HTML in the book, :func:`format_table` text beside it.

    One display object carries both forms: ``text/html`` (:func:`nctwin.report.html.html_table`,
    floats to ``digits`` significant digits, the paper's columns grouped), which the book
    renders, and ``text/plain``, exactly the text ``print(format_table(df))`` prints (without
    its final newline); nbval compares both. A chapter cell calls ``show(table)`` where it
    printed ``format_table(table)`` and displayed the frame.

    ``notes`` names a column of texts shown as numbered footnotes below the table, the column
    holding their numbers (``[1]`` ...); it is left out where no row has a text. ``transpose``
    is :func:`~nctwin.report.html.html_table`'s (``True``: one row per column, e.g. a claim per
    column and a seed per row); the text is the table as it is.
    """
    from IPython.display import display

    body, footnotes = _footnoted(df, notes) if notes else (df, [])
    text = _with_footnotes(format_table(body), footnotes)
    page = html_table(body, digits=digits, notes=footnotes, transpose=transpose)
    display({"text/plain": text, "text/html": page}, raw=True)


def show_paper(df: pd.DataFrame, name: str | None = None) -> None:
    """Display a paper table once: the citation as caption, the notes as footnotes.

    ``text/plain`` is :func:`format_paper_table`; the HTML shows the numbers with six
    significant digits, as the CSV holds them.
    """
    from IPython.display import display

    title, body, footnotes = _paper_parts(df, name)
    page = html_table(body, digits=6, prefix="", caption=" | ".join(title), notes=footnotes)
    display({"text/plain": format_paper_table(df, name), "text/html": page}, raw=True)
