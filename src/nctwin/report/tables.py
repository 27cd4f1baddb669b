r"""Paper-vs-reproduced tables and the results contract.

Every chapter prints its reproduced numbers beside the paper's own, and writes them to
``results/<notebook-stem>/`` so that the book, the tests and a reader can all check them.
This module holds everything that touches those tables; it does no physics.

Conventions
-----------
Paper tables
    ``data/papers/<name>.csv``, one file per table of a paper (or per block of numbers quoted in
    its prose). Every row cites its source in the columns ``paper``, ``table`` and, where the text
    tells, ``page_or_section``; a free-text ``note`` column records transcription caveats. The
    numbers are exactly as printed. ``data/papers/README.md`` lists the files.
Data location
    :mod:`nctwin.paths`: the data folder is ``<repo>/data`` (the package is installed editable)
    or ``$NCTWIN_DATA``, with the paper tables in its ``papers/`` sub-folder; results go to
    ``<repo>/results`` or ``$NCTWIN_RESULTS``. Both are read at call time.
Errors
    Relative errors are in percent,

    .. math:: e = \frac{|\hat T - T|}{T} \times 100\,\%,

    with :math:`\hat T` predicted and :math:`T` measured, and accuracy is :math:`100\,\% - e`,
    as in all five papers.
Joining
    :func:`side_by_side` matches numeric keys after rounding them to ``sig_digits`` significant
    digits (default 6), so that a feed of ``np.float32(0.3)`` meets the paper's ``0.3``. The
    paper's keys carry at most four significant digits, so six never merges distinct keys.
Results files
    CSV with ``,`` separators, ``\n`` line ends, no index, floats written with
    :data:`FLOAT_FORMAT` (``"%.6g"``, six significant digits); ``claims.json`` is a list of
    ``{"id", "text", "value", "op", "threshold", "holds", "whose", "status"}`` (and ``"unmet"``
    where a claim's conditions are unmet, :class:`Claim`) with sorted keys and an indent of 2.
    Both are written atomically: to a temporary file in the target folder, then ``os.replace``.
"""

from __future__ import annotations

import json
import math
import operator
import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .. import paths
from ..cache import atomic_write_text
from .html import html_table

__all__ = [
    "CITING_COLUMNS",
    "FLOAT_FORMAT",
    "META_COLUMNS",
    "OPS",
    "WHOSE",
    "Claim",
    "UnknownTableError",
    "accuracy_pct",
    "available_tables",
    "error_pct",
    "format_paper_table",
    "format_table",
    "load_paper_table",
    "paper_tables",
    "papers_dir",
    "show",
    "show_paper",
    "side_by_side",
    "write_claims",
    "write_table",
]

CITING_COLUMNS: tuple[str, ...] = ("paper", "table", "page_or_section")
"""Columns that cite the source of each row of a paper table."""

META_COLUMNS: tuple[str, ...] = (*CITING_COLUMNS, "note")
"""Columns of a paper table that are not numbers to reproduce."""

FLOAT_FORMAT: str = "%.6g"
"""printf-style format of floats in results CSV files and in :func:`format_table`."""

#: Whose a claim is (:attr:`Claim.whose`).
WHOSE = ("paper", "ours")

OPS: dict[str, Callable[[float, float], bool]] = {
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
    "==": operator.eq,
}
"""Comparison operators a :class:`Claim` may use."""

_SIMPLE_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


class UnknownTableError(KeyError):
    """A paper table name that has no CSV file; the message lists the available names."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


# ----------------------------------------------------------------------------------------------
# Locations


def papers_dir() -> Path:
    """Return the folder of the paper tables, ``paths.data_dir() / "papers"``.

    ``paths.data_dir()`` is the package's shipped data, or ``$NCTWIN_DATA`` if set, read at call
    time.
    """
    return paths.data_dir() / "papers"


def _check_simple_name(value: str, what: str) -> str:
    """Reject names that could leave their folder (``..``, ``/``) or are empty."""
    if not isinstance(value, str) or not _SIMPLE_NAME.match(value) or ".." in value:
        raise ValueError(
            f"{what} must be a plain file name of letters, digits, '_', '-' or '.', got {value!r}"
        )
    return value


# ----------------------------------------------------------------------------------------------
# Paper tables


def available_tables(directory: Path | None = None) -> list[str]:
    """List the names of the paper tables, sorted.

    Parameters
    ----------
    directory
        Folder to list; default :func:`papers_dir`.

    Returns
    -------
    list of str
        File stems of ``*.csv`` in the folder, e.g. ``"chien2023_table1"``.
    """
    folder = papers_dir() if directory is None else Path(directory)
    return sorted(p.stem for p in folder.glob("*.csv"))


def paper_tables(paper: str, selected: Iterable[str] | None = None) -> list[str]:
    """List the tables of one paper, e.g. ``paper_tables("chien2023")``.

    Parameters
    ----------
    paper
        Paper key, the file-name prefix before the first ``_`` (``"chien2023"``, ``"sun2022"``,
        ``"lee2022"``, ``"denkena2020"``, ``"zhang2023"``).
    selected
        Paper keys to show; ``None`` selects every paper. A paper not in ``selected`` gets an
        empty list (this is how a notebook's ``papers`` parameter filters its sections).

    Returns
    -------
    list of str
        The paper's numbered tables first (``table1``, ``table2``, ... in number order), then its
        other files in alphabetical order, its ``summary`` last.
    """
    if selected is not None and paper not in set(selected):
        return []
    names = [name for name in available_tables() if name.split("_", 1)[0] == paper]
    return sorted(names, key=_table_order)


def _table_order(name: str) -> tuple[int, int, str]:
    """Sort key: ``<paper>_table<N>`` by N, then other names, then ``<paper>_summary``."""
    match = re.fullmatch(r"[^_]+_table(\d+)", name)
    if match:
        return (0, int(match.group(1)), name)
    return (2 if name.endswith("_summary") else 1, 0, name)


def load_paper_table(name: str, *, directory: Path | None = None) -> pd.DataFrame:
    """Read one paper table, ``data/papers/<name>.csv``.

    Parameters
    ----------
    name
        Table name, with or without ``.csv`` (see :func:`available_tables`).
    directory
        Folder to read from; default :func:`papers_dir`.

    Returns
    -------
    pandas.DataFrame
        The table as transcribed; numbers exactly as the CSV holds them.

    Raises
    ------
    UnknownTableError
        (a ``KeyError``) if there is no such table; the message lists the available names.
    ValueError
        If ``name`` is not a plain file name, or the file lacks the citing columns ``paper`` and
        ``table`` or has an empty ``table`` cell.
    """
    stem = name[:-4] if name.endswith(".csv") else name
    _check_simple_name(stem, "name")
    folder = papers_dir() if directory is None else Path(directory)
    path = folder / f"{stem}.csv"
    if not path.is_file():
        names = ", ".join(available_tables(folder)) or "(none)"
        raise UnknownTableError(f"no paper table {stem!r} in {folder}; available: {names}")
    df = pd.read_csv(path)
    _check_citing(df, path)
    return df


def _check_citing(df: pd.DataFrame, path: Path) -> None:
    """Raise ValueError unless every row names its paper and table."""
    missing = [c for c in ("paper", "table") if c not in df.columns]
    if missing:
        raise ValueError(f"{path.name}: missing citing column(s) {missing}")
    for column in ("paper", "table"):
        empty = df[column].isna() | (df[column].astype(str).str.strip() == "")
        if empty.any():
            rows = [int(i) for i in np.flatnonzero(empty.to_numpy())]
            raise ValueError(f"{path.name}: empty {column!r} cell in data row(s) {rows}")


# ----------------------------------------------------------------------------------------------
# Errors


def error_pct(predicted: Any, measured: Any, *, signed: bool = False) -> Any:
    r"""Relative error in percent, :math:`|\hat T - T| / T \times 100`, or with ``signed``
    :math:`100 (\hat T - T) / T` (negative: an underestimate). The package's one percent error.

    Parameters
    ----------
    predicted
        Predicted value(s) :math:`\hat T`; scalar or array-like.
    measured
        Measured value(s) :math:`T`, all > 0; broadcast against ``predicted``.
    signed
        Keep the sign.

    Returns
    -------
    float or numpy.ndarray
        A float for scalar inputs, else an array of the broadcast shape.

    Raises
    ------
    ValueError
        If any ``measured`` is <= 0 (the error relative to it is undefined).

    Examples
    --------
    >>> round(error_pct(45.3, 44.5), 2)  # Chien et al. 2023, Table 1, I, 75 mm/s, 0.4 mm
    1.8
    """
    p = np.asarray(predicted, dtype=float)
    m = np.asarray(measured, dtype=float)
    if np.any(m <= 0):
        raise ValueError(f"measured must be > 0, got {m[m <= 0].ravel()[:5].tolist()}")
    out = 100.0 * (p - m) / m if signed else np.abs(p - m) / m * 100.0
    return float(out) if out.ndim == 0 else out


def accuracy_pct(predicted: Any, measured: Any) -> Any:
    """Accuracy in percent, ``100 - error_pct(predicted, measured)``.

    Examples
    --------
    >>> round(accuracy_pct(2172.4, 2169.1), 1)  # Lee et al. 2022, set 1: printed 99.8 %
    99.8
    """
    return 100.0 - error_pct(predicted, measured)


# ----------------------------------------------------------------------------------------------
# Paper beside ours


def _round_sig(values: pd.Series, sig_digits: int) -> pd.Series:
    """Round a numeric series to ``sig_digits`` significant digits (NaN stays NaN)."""
    x = values.to_numpy(dtype=float, na_value=np.nan)
    out = np.full_like(x, np.nan)
    finite = np.isfinite(x)
    out[finite] = [float(f"{v:.{sig_digits}g}") for v in x[finite]]
    return pd.Series(out, index=values.index)


def _join_keys(
    ours: pd.DataFrame, paper: pd.DataFrame, on: Sequence[str], sig_digits: int
) -> tuple[pd.DataFrame, pd.DataFrame, list[str]]:
    """Add normalised key columns to copies of both frames; return them and the key names."""
    left, right = paper.copy(), ours.copy()
    keys = []
    for i, column in enumerate(on):
        key = f"__key{i}"
        a, b = paper[column], ours[column]
        a_num, b_num = pd.api.types.is_numeric_dtype(a), pd.api.types.is_numeric_dtype(b)
        if a_num != b_num:
            raise TypeError(
                f"key column {column!r} is numeric in one frame and not in the other "
                f"(paper: {a.dtype}, ours: {b.dtype})"
            )
        left[key] = _round_sig(a, sig_digits) if a_num else a.astype(str)
        right[key] = _round_sig(b, sig_digits) if b_num else b.astype(str)
        keys.append(key)
    return left, right, keys


def side_by_side(
    ours: pd.DataFrame,
    paper: pd.DataFrame,
    on: Sequence[str],
    columns: Sequence[str] | None = None,
    *,
    prefix: str = "paper_",
    sig_digits: int = 6,
) -> pd.DataFrame:
    """Put our reproduced columns beside the paper's, one row per paper row.

    A left join on the paper table: every paper row appears, in the paper's order, even when we
    have no number for it (our columns are then NaN); our rows without a paper row are dropped.

    Parameters
    ----------
    ours
        Reproduced table; must hold the ``on`` columns, at most one row per key.
    paper
        Paper table from :func:`load_paper_table`.
    on
        Key columns present in both, e.g. ``["toolpath", "feed_mm_s", "tol_mm"]``. Numeric keys
        match after rounding both sides to ``sig_digits`` significant digits.
    columns
        Paper columns to bring in; default every column except the keys and
        :data:`META_COLUMNS`.
    prefix
        Prefix of the paper's columns in the result.
    sig_digits
        Significant digits of numeric keys for matching.

    Returns
    -------
    pandas.DataFrame
        The keys (paper's values), our non-key columns, the paper's ``columns`` prefixed with
        ``prefix``, and ``<prefix>source`` (``"<paper>, <table>"``) citing each row.

    Raises
    ------
    KeyError
        If a key or a requested column is missing.
    TypeError
        If a key is numeric in one frame and not in the other.
    ValueError
        If ``on`` is empty, ``ours`` repeats a key, or our column names clash with the result's.
    """
    on = list(on)
    if not on:
        raise ValueError("on must name at least one key column")
    for frame_name, frame in (("ours", ours), ("paper", paper)):
        missing = [c for c in on if c not in frame.columns]
        if missing:
            raise KeyError(f"key column(s) {missing} missing from {frame_name}")
    if columns is None:
        columns = [c for c in paper.columns if c not in on and c not in META_COLUMNS]
    missing = [c for c in columns if c not in paper.columns]
    if missing:
        raise KeyError(f"column(s) {missing} missing from paper")

    left, right, keys = _join_keys(ours, paper, on, sig_digits)
    if right.duplicated(keys).any():
        dup = right.loc[right.duplicated(keys, keep=False), on].drop_duplicates()
        raise ValueError(f"ours has more than one row per key {on}: {dup.to_dict('records')}")

    ours_cols = [c for c in ours.columns if c not in on]
    paper_out = {f"{prefix}{c}": left[c] for c in columns}
    clash = sorted(set(ours_cols) & ({*paper_out, f"{prefix}source"} | set(on)))
    if clash:
        raise ValueError(f"our column(s) {clash} clash with the paper's columns in the result")

    cited = left[keys].assign(**paper_out)
    cited[f"{prefix}source"] = _source(paper)
    merged = cited.merge(right[keys + ours_cols], on=keys, how="left", sort=False)
    out = pd.concat([paper[on].reset_index(drop=True), merged.drop(columns=keys)], axis=1)
    return out[[*on, *ours_cols, *paper_out, f"{prefix}source"]]


def _source(paper: pd.DataFrame) -> list[str]:
    """Citation strings ``"<paper>, <table>"`` per row (missing parts left out)."""
    cols = [c for c in ("paper", "table") if c in paper.columns]
    rows = paper[cols].itertuples(index=False, name=None)
    return [", ".join(v for v in row if isinstance(v, str) and v) for row in rows]


# ----------------------------------------------------------------------------------------------
# Claims


@dataclass(frozen=True)
class Claim:
    """One checkable statement of a paper: ``value op threshold``.

    Parameters
    ----------
    id
        Short stable identifier, e.g. ``"bilstm_beats_cam"``.
    text
        The claim in words, citing the paper, e.g. ``"BiLSTM error < 2.5 % (Chien, Table 1)"``.
    value
        Our reproduced number (converted to float). NaN means "not reproduced": the claim fails.
    op
        One of ``"<"``, ``"<="``, ``">"``, ``">="``, ``"=="``.
    threshold
        The bound the value is compared with, in the same unit as ``value``.
    whose
        ``"paper"``: the paper's own claim at its own level; ``"ours"``: a check of the
        project's own (a program beyond the paper's, an ablation), which cites no paper section.
    requires
        Ids of the conditions (:class:`~nctwin.report.conditions.Condition`) the claim is
        tested under: where one is unmet, the claim is not tested.
    unmet
        Those of ``requires`` that are unmet (set by
        :func:`~nctwin.report.claims.report_claims` from the chapter's conditions).
    seeds_passing, seeds
        For a learned claim judged on an ensemble: how many of the ``seeds`` single networks
        pass the claim on their own ("k of n"); None elsewhere.
    interval
        For a learned claim: a bootstrap interval of ``value`` over the seeds
        (:func:`~nctwin.report.claims.bootstrap_interval`), ``(low, high)``; None elsewhere.

    Raises
    ------
    ValueError
        If ``op`` is not one of :data:`OPS`, ``whose`` not one of :data:`WHOSE`, or
        ``seeds_passing`` outside 0 to ``seeds``.
    """

    id: str
    text: str
    value: float
    op: str
    threshold: float
    whose: str = "paper"
    requires: tuple[str, ...] = ()
    unmet: tuple[str, ...] = ()
    seeds_passing: int | None = None
    seeds: int | None = None
    interval: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        if self.op not in OPS:
            raise ValueError(f"op must be one of {list(OPS)}, got {self.op!r}")
        if self.whose not in WHOSE:
            raise ValueError(f"whose = {self.whose!r} is out of range: allowed {', '.join(WHOSE)}")
        if (self.seeds_passing is None) != (self.seeds is None) or (
            self.seeds is not None and not 0 <= self.seeds_passing <= self.seeds
        ):
            raise ValueError(
                f"claim {self.id!r}: seeds_passing = {self.seeds_passing!r} is out of range: "
                f"allowed 0 to seeds ({self.seeds!r}), both set or neither"
            )
        if self.interval is not None:
            object.__setattr__(self, "interval", tuple(float(v) for v in self.interval))
        object.__setattr__(self, "value", float(self.value))
        object.__setattr__(self, "threshold", float(self.threshold))
        object.__setattr__(self, "requires", tuple(self.requires))
        object.__setattr__(self, "unmet", tuple(self.unmet))

    @property
    def holds(self) -> bool:
        """Whether ``value op threshold`` is true; False if either number is NaN."""
        if math.isnan(self.value) or math.isnan(self.threshold):
            return False
        return bool(OPS[self.op](self.value, self.threshold))

    @property
    def status(self) -> str:
        """``"not tested"`` where a condition it requires is unmet (it neither holds nor
        fails), else ``"holds"`` or ``"fails"``."""
        if self.unmet:
            return "not tested"
        return "holds" if self.holds else "fails"

    def to_dict(self) -> dict[str, Any]:
        """Return the JSON record ``{"id", "text", "value", "op", "threshold", "holds", "whose",
        "status"}``, and ``"unmet"`` (the unmet conditions' ids) where there are any,
        ``"seeds_passing"`` and ``"seeds"``, and ``"interval"`` (``[low, high]``) where set.

        NaN numbers become ``None`` (JSON ``null``), since JSON has no NaN.
        """
        out = {
            "id": self.id,
            "text": self.text,
            "value": None if math.isnan(self.value) else self.value,
            "op": self.op,
            "threshold": None if math.isnan(self.threshold) else self.threshold,
            "holds": self.holds,
            "whose": self.whose,
            "status": self.status,
        }
        if self.unmet:
            out["unmet"] = list(self.unmet)
        if self.seeds is not None:
            out |= {"seeds_passing": self.seeds_passing, "seeds": self.seeds}
        if self.interval is not None:
            out["interval"] = list(self.interval)
        return out


# ----------------------------------------------------------------------------------------------
# Results files


def write_table(stem: str, name: str, df: pd.DataFrame, *, results_dir: Path | None = None) -> Path:
    """Write a reproduced table to ``results/<stem>/<name>.csv`` atomically.

    Parameters
    ----------
    stem
        Notebook stem, e.g. ``"chien2023_bilstm"``.
    name
        Table name, e.g. ``"table1"``.
    df
        Table to write; the index is not written.
    results_dir
        Results folder; default ``paths.results_dir()`` (``<repo>/results`` or ``$NCTWIN_RESULTS``).

    Returns
    -------
    pathlib.Path
        Path of the written file. Floats are formatted with :data:`FLOAT_FORMAT`.
    """
    folder = _results_folder(stem, results_dir)
    text = df.to_csv(index=False, float_format=FLOAT_FORMAT, lineterminator="\n")
    return atomic_write_text(folder / f"{_check_simple_name(name, 'name')}.csv", text)


def write_claims(stem: str, claims: Iterable[Claim], *, results_dir: Path | None = None) -> Path:
    """Write the claims to ``results/<stem>/claims.json`` atomically.

    Parameters
    ----------
    stem
        Notebook stem.
    claims
        Claims in the order they should appear; their ids must be unique.
    results_dir
        Results folder; default ``paths.results_dir()``.

    Returns
    -------
    pathlib.Path
        Path of the written file: a JSON list of :meth:`Claim.to_dict` records, keys sorted,
        indent 2, trailing newline.

    Raises
    ------
    ValueError
        If two claims share an id.
    """
    records = [c.to_dict() for c in claims]
    ids = [r["id"] for r in records]
    if len(set(ids)) != len(ids):
        raise ValueError(f"claim ids must be unique, got {ids}")
    text = json.dumps(records, sort_keys=True, indent=2, ensure_ascii=False) + "\n"
    return atomic_write_text(_results_folder(stem, results_dir) / "claims.json", text)


def _results_folder(stem: str, folder: Path | None) -> Path:
    base = paths.results_dir() if folder is None else Path(folder)
    return base / _check_simple_name(stem, "stem")


# ----------------------------------------------------------------------------------------------
# Plain-text rendering


def _format_float(value: float) -> str:
    return FLOAT_FORMAT % value


def format_table(df: pd.DataFrame) -> str:
    """Render a table as deterministic plain text for ``print()`` in notebooks.

    Floats use :data:`FLOAT_FORMAT`, missing values print as ``-``, no index, every column and
    row shown, no line wrapping: the same frame always gives the same text, so nbval can compare
    it bit for bit.
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
        Paper table from :func:`load_paper_table`.
    name
        Table name to show in the title, e.g. ``"chien2023_table1"``.
    """
    title, body, footnotes = _paper_parts(df, name)
    lines = [" | ".join(title), format_table(body)] if title else [format_table(body)]
    lines += [f"[{i}] {text}" for i, text in enumerate(footnotes, start=1)]
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------------
# One table per result: HTML for the book, the same plain text for nbval


def show(df: pd.DataFrame, *, digits: int = 4) -> None:
    """Display a table once: compact HTML in the book, :func:`format_table` text for nbval.

    One display object carries both forms: ``text/html`` (:func:`nctwin.report.html.html_table`,
    floats to ``digits`` significant digits, the paper's columns grouped), which the book
    renders, and ``text/plain``, exactly the text ``print(format_table(df))`` prints (without
    its final newline), which nbval compares. A chapter cell calls ``show(table)`` where it
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
