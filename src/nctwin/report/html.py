"""Tables as compact HTML for the book, through pandas' :class:`~pandas.io.formats.style.Styler`.

A chapter shows each result once (:func:`nctwin.report.display.show`): the book renders the HTML
written here, nbval compares the plain text of :func:`nctwin.report.display.format_table` (and,
in the cells it checks, this HTML too). The HTML fits a page column: short headers with the unit
in parentheses (the full column name in the header's ``title``), floats rounded to a few
significant digits, no index, numbers in cells of the class ``nctwin-num`` (right-aligned, never
broken), and the paper's columns grouped under one "paper" header. The paper's cells are tinted
by the table's own style rules, which take their colours from ``book/_css/nctwin.css``
(``--nctwin-paper-bg``, ``--nctwin-paper-rule``). The table's id is derived from its content, so
the same frame always gives the same HTML and a page's tables do not share style rules.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from html import escape
from typing import Any

import numpy as np
import pandas as pd
from pandas.io.formats.style import Styler

__all__ = ["TRANSPOSE_MIN_COLUMNS", "format_value", "html_table", "short_header"]

#: A table of at least this many columns and at most a third as many rows is shown transposed
#: (one row per column), so that it fits the page column (``transpose=None``).
TRANSPOSE_MIN_COLUMNS = 13

#: Style of the paper's cells and of the rule before the first of them: colours from the book's
#: stylesheet (``book/_css/nctwin.css``).
_PAPER_CSS = "background: var(--nctwin-paper-bg)"
_START_CSS = {
    "columns": "border-left: var(--nctwin-paper-rule)",
    "index": "border-top: var(--nctwin-paper-rule)",
}

#: Column-name suffixes and the header text they become, longest match first.
_UNITS: tuple[tuple[str, str], ...] = (
    ("_err_pct", "err (%)"),
    ("_mm_s2", "(mm/s²)"),
    ("_mm_s", "(mm/s)"),
    ("_mm_min", "(mm/min)"),
    ("_pct", "(%)"),
    ("_mm", "(mm)"),
    ("_um", "(µm)"),
    ("_ms", "(ms)"),
    ("_hz", "(Hz)"),
    ("_rpm", "(rpm)"),
    ("_n", "(N)"),
    ("_s", "(s)"),
    ("_h", "(h)"),
)


def short_header(column: str, prefix: str = "paper_") -> str:
    """A column name as a short header: ``prefix`` dropped, a unit suffix as ``(unit)``.

    Examples
    --------
    >>> short_header("paper_bilstm_err_pct"), short_header("feed_mm_s"), short_header("tol_mm")
    ('bilstm err (%)', 'feed (mm/s)', 'tol (mm)')
    """
    name = column[len(prefix) :] if prefix and column.startswith(prefix) else column
    for suffix, unit in _UNITS:
        if name.endswith(suffix) and len(name) > len(suffix):
            name = f"{name[: -len(suffix)]} {unit}"
            break
    return name.replace("_", " ")


def format_value(value: Any, digits: int = 4) -> str:
    """One cell's text: a float to ``digits`` significant digits, but never fewer digits than
    its integer part (2282.8 -> ``"2283"``), in scientific notation only below 1e-3 or from
    1e7; NaN and None as ``"-"``; anything else as ``str``.

    Examples
    --------
    >>> format_value(99.95001796), format_value(2282.82), format_value(0.0026178), format_value(3.0)
    ('99.95', '2283', '0.002618', '3')
    """
    if value is None or (isinstance(value, float | np.floating) and math.isnan(value)):
        return "-"
    if not isinstance(value, float | np.floating):
        return str(value)
    x = float(value)
    if x == 0 or not math.isfinite(x):
        return f"{x:g}"
    if not 1e-3 <= abs(x) < 1e7:
        return f"{x:.{max(digits - 1, 0)}e}"
    decimals = max(digits - 1 - math.floor(math.log10(abs(x))), 0)
    text = f"{x:.{decimals}f}"
    return text.rstrip("0").rstrip(".") if decimals else text


def html_table(
    df: pd.DataFrame,
    *,
    digits: int = 4,
    prefix: str = "paper_",
    caption: str = "",
    notes: Sequence[str] = (),
    transpose: bool | None = None,
) -> str:
    """Render a table as compact HTML, ``<div class="nctwin-table"><style>...<table>...``.

    Parameters
    ----------
    df
        Table to render, every row and column; the index is not shown.
    digits
        Significant digits of floats (:func:`format_value`).
    prefix
        Prefix of the paper's columns, grouped under one "paper" header; ``""`` for none. A
        ``<prefix>source`` column that is the same on every row goes into that header instead.
    caption
        Title above the table; empty for none.
    notes
        Footnotes below the table, numbered from 1.
    transpose
        Show one row per column (the first column's values head the columns); ``None``: when
        the table has at least :data:`TRANSPOSE_MIN_COLUMNS` columns and at most a third as
        many rows. The paper's rows are then grouped instead of its columns.

    Returns
    -------
    str
        The HTML; the same arguments always give the same text.
    """
    body = df.reset_index(drop=True)
    group = "paper"
    source = f"{prefix}source"
    if prefix and source in body.columns and len(body) and body[source].nunique(dropna=False) == 1:
        group = f"paper ({body[source].iloc[0]})"
        body = body.drop(columns=source)
    columns = [str(c) for c in body.columns]
    if transpose is None:
        transpose = len(columns) >= TRANSPOSE_MIN_COLUMNS and 3 * len(body) <= len(columns)
    key = repr((body.to_csv(), columns, digits, prefix, group, caption, list(notes), transpose))
    uuid = hashlib.sha256(key.encode()).hexdigest()[:12]
    if transpose:
        styler = _transposed(body, columns, prefix, digits, uuid)
    else:
        styler = _upright(body, columns, prefix, group, digits, uuid)
    if caption:
        styler.set_caption(escape(caption))
    out = ['<div class="nctwin-table">', styler.to_html().rstrip()]
    if notes:
        items = "".join(f"<li>{escape(n)}</li>" for n in notes)
        out.append(f'<ol class="nctwin-notes">{items}</ol>')
    out.append("</div>")
    return "\n".join(out)


def _upright(
    body: pd.DataFrame, columns: list[str], prefix: str, group: str, digits: int, uuid: str
) -> Styler:
    """One column per column: the paper's under a ``group`` header (when there are any)."""
    paper = [_is_paper(c, prefix) for c in columns]
    frame = body.set_axis(range(len(columns)), axis=1)
    if any(paper):
        labels = [(group if p else "", j) for j, p in enumerate(paper)]
        frame.columns = pd.MultiIndex.from_tuples(labels)
    styler = Styler(frame, uuid=uuid, cell_ids=False).hide(axis="index")
    styler.format(lambda v: _text(format_value(v, digits)))
    styler.format_index(
        lambda j: _header(columns[j], prefix), axis="columns", level=frame.columns.nlevels - 1
    )
    if any(paper):
        styler.format_index(escape="html", axis="columns", level=0)
    numeric = [_num_class(body, j) for j in range(len(columns))]
    styler.set_td_classes(pd.DataFrame([numeric] * len(frame), columns=frame.columns))
    return _group(styler, list(frame.columns), paper, "columns")


def _transposed(
    body: pd.DataFrame, columns: list[str], prefix: str, digits: int, uuid: str
) -> Styler:
    """One row per column after the first, whose values head the columns; the paper's rows
    labelled ``(paper)``."""
    paper = [_is_paper(c, prefix) for c in columns]
    frame = body.iloc[:, 1:].T.set_axis(range(1, len(columns)), axis=0)
    frame = frame.set_axis(range(len(body)), axis=1)
    frame.columns.name = _header(columns[0], prefix)
    heads = [_text(format_value(v, digits)) for v in body.iloc[:, 0]]
    styler = Styler(frame, uuid=uuid, cell_ids=False)
    styler.format(lambda v: _text(format_value(v, digits)))
    styler.format_index(heads.__getitem__, axis="columns")
    styler.format_index(
        lambda j: _header(columns[j], prefix, " (paper)" if paper[j] else ""), axis="index"
    )
    numeric = [[_num_class(body, j)] * len(body) for j in range(1, len(columns))]
    styler.set_td_classes(pd.DataFrame(numeric, index=frame.index, columns=frame.columns))
    return _group(styler, list(frame.index), paper[1:], "index")


def _group(styler: Styler, labels: list[Any], paper: list[bool], axis: str) -> Styler:
    """Tint the paper's columns (or rows, ``axis="index"``) and rule off the first of them."""
    first = paper.index(True) if any(paper) else -1
    styles = {}
    for k, (label, is_paper) in enumerate(zip(labels, paper, strict=True)):
        if is_paper:
            props = _PAPER_CSS + (f"; {_START_CSS[axis]}" if k == first else "")
            styles[label] = [{"selector": "", "props": props}]
    if styles:
        styler.set_table_styles(styles, axis=0 if axis == "columns" else 1)
    return styler


def _is_paper(column: str, prefix: str) -> bool:
    """Whether a column is the paper's (its name starts with ``prefix``)."""
    return bool(prefix) and column.startswith(prefix)


def _num_class(body: pd.DataFrame, j: int) -> str:
    """``"nctwin-num"`` (right-aligned, never broken) for a column ``j`` of numbers, else ``""``;
    booleans are not numbers."""
    values = body.iloc[:, j]
    numeric = pd.api.types.is_numeric_dtype(values) and not pd.api.types.is_bool_dtype(values)
    return "nctwin-num" if numeric else ""


def _header(column: str, prefix: str, suffix: str = "") -> str:
    """A header cell's content: the short header (:func:`short_header`) and ``suffix``, with the
    full column name as its ``title``."""
    text = escape(short_header(column, prefix) + suffix)
    return f'<span title="{escape(column)}">{text}</span>'


def _text(text: str) -> str:
    """Escaped cell text that may break after ``_`` and ``/`` (long program names wrap)."""
    return escape(text).replace("_", "_<wbr>").replace("/", "/<wbr>")
