"""Tables as compact HTML for the book.

A chapter shows each result once (:func:`nctwin.report.display.show`): the book renders the HTML
written here, nbval compares the plain text of :func:`nctwin.report.display.format_table`. The
HTML fits a page column: short headers with the unit in parentheses (the full column name in the
header's ``title``), floats rounded to a few significant digits, no index, and the paper's
columns grouped under one "paper" header with the class ``nctwin-paper`` (styled by
``book/_css/nctwin.css``). The same frame always gives the same HTML (no random ids), so nbval
can compare it too.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from html import escape
from typing import Any

import numpy as np
import pandas as pd

__all__ = ["TRANSPOSE_MIN_COLUMNS", "format_value", "html_table", "short_header"]

#: A table of at least this many columns and at most a third as many rows is shown transposed
#: (one row per column), so that it fits the page column (``transpose=None``).
TRANSPOSE_MIN_COLUMNS = 13

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
    """Render a table as compact HTML, ``<div class="nctwin-table"><table>...``.

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
        The HTML; the same frame always gives the same text.
    """
    body = df.reset_index(drop=True)
    group = "paper"
    source = f"{prefix}source"
    if prefix and source in body.columns and len(body) and body[source].nunique(dropna=False) == 1:
        group = f"paper ({body[source].iloc[0]})"
        body = body.drop(columns=source)
    columns = [str(c) for c in body.columns]
    paper = [bool(prefix) and c.startswith(prefix) for c in columns]
    first = paper.index(True) if any(paper) else -1
    numeric = [
        pd.api.types.is_numeric_dtype(body[c]) and not pd.api.types.is_bool_dtype(body[c])
        for c in body.columns
    ]

    def attr(j: int, *, cell: bool) -> str:
        names = ["nctwin-paper"] * paper[j] + ["nctwin-start"] * (j == first)
        names += ["nctwin-num"] * (cell and numeric[j])
        return f' class="{" ".join(names)}"' if names else ""

    if transpose is None:
        transpose = len(columns) >= TRANSPOSE_MIN_COLUMNS and 3 * len(body) <= len(columns)
    out = ['<div class="nctwin-table"><table>']
    if caption:
        out.append(f"<caption>{escape(caption)}</caption>")
    if transpose:
        heads = "".join(f"<th>{_text(format_value(v, digits))}</th>" for v in body.iloc[:, 0])
        first_head = escape(short_header(columns[0], prefix))
        out.append(
            f'<thead><tr><th title="{escape(columns[0])}">{first_head}</th>{heads}</tr></thead>'
            "<tbody>"
        )
        for j in range(1, len(columns)):
            names = ["nctwin-paper"] * paper[j] + ["nctwin-start-row"] * (j == first)
            row_attr = f' class="{" ".join(names)}"' if names else ""
            label = short_header(columns[j], prefix) + (" (paper)" if paper[j] else "")
            td = '<td class="nctwin-num">' if numeric[j] else "<td>"
            cells = "".join(f"{td}{_text(format_value(v, digits))}</td>" for v in body.iloc[:, j])
            out.append(
                f'<tr{row_attr}><th title="{escape(columns[j])}">{escape(label)}</th>{cells}</tr>'
            )
        out.append("</tbody></table>")
        return _close(out, notes)
    out.append("<thead>")
    if any(paper):
        ours = f'<th colspan="{first}"></th>' if first else ""
        out.append(
            f'<tr>{ours}<th colspan="{sum(paper)}" class="nctwin-paper nctwin-start">'
            f"{escape(group)}</th></tr>"
        )
    headers = (
        f'<th{attr(j, cell=False)} title="{escape(c)}">{escape(short_header(c, prefix))}</th>'
        for j, c in enumerate(columns)
    )
    out.append(f"<tr>{''.join(headers)}</tr></thead><tbody>")
    for row in body.itertuples(index=False, name=None):
        cells = (
            f"<td{attr(j, cell=True)}>{_text(format_value(v, digits))}</td>"
            for j, v in enumerate(row)
        )
        out.append(f"<tr>{''.join(cells)}</tr>")
    out.append("</tbody></table>")
    return _close(out, notes)


def _text(text: str) -> str:
    """Escaped cell text that may break after ``_`` and ``/`` (long program names wrap)."""
    return escape(text).replace("_", "_<wbr>").replace("/", "/<wbr>")


def _close(out: list[str], notes: Sequence[str]) -> str:
    """Append the footnotes and close the ``div``."""
    if notes:
        items = "".join(f"<li>{escape(n)}</li>" for n in notes)
        out.append(f'<ol class="nctwin-notes">{items}</ol>')
    out.append("</div>")
    return "\n".join(out)
