r"""The papers' tables: where they are, how they load, and ours beside them.

Conventions
-----------
Paper tables
    ``data/papers/<name>.csv``, one file per table of a paper (or per block of numbers quoted in
    its prose). Every row cites its source in the columns ``paper``, ``table`` and, where the text
    tells, ``page_or_section``; a free-text ``note`` column records transcription caveats. The
    numbers are exactly as printed. ``data/papers/README.md`` lists the files.
Data location
    :mod:`nctwin.paths`: the data folder is ``<repo>/data`` (the package is installed editable)
    or ``$NCTWIN_DATA``, with the paper tables in its ``papers/`` sub-folder. It is read at call
    time.
Joining
    :func:`side_by_side` matches numeric keys after rounding them to ``sig_digits`` significant
    digits (default 6), so that a feed of ``np.float32(0.3)`` meets the paper's ``0.3``. The
    paper's keys carry at most four significant digits, so six never merges distinct keys.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from .. import paths

__all__ = [
    "CITING_COLUMNS",
    "META_COLUMNS",
    "UnknownTableError",
    "available_tables",
    "check_simple_name",
    "load_paper_table",
    "paper_tables",
    "papers_dir",
    "side_by_side",
]

CITING_COLUMNS: tuple[str, ...] = ("paper", "table", "page_or_section")
"""Columns that cite the source of each row of a paper table."""

META_COLUMNS: tuple[str, ...] = (*CITING_COLUMNS, "note")
"""Columns of a paper table that are not numbers to reproduce."""

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


def check_simple_name(value: str, what: str) -> str:
    """Reject names that could leave their folder (``..``, ``/``) or are empty."""
    if not isinstance(value, str) or not _SIMPLE_NAME.match(value) or ".." in value:
        raise ValueError(
            f"{what} must be a plain file name of letters, digits, '_', '-' or '.', got {value!r}"
        )
    return value


# ----------------------------------------------------------------------------------------------
# Loading


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
    check_simple_name(stem, "name")
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
