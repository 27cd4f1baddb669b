r"""The results contract: reproduced tables and claims written to ``results/<notebook-stem>/``,
so that the book, the tests and a reader can all check them.

Conventions
-----------
Location
    ``<repo>/results`` or ``$NCTWIN_RESULTS`` (:func:`nctwin.paths.results_dir`), read at call
    time.
Results files
    CSV with ``,`` separators, ``\n`` line ends, no index, floats written with
    :data:`FLOAT_FORMAT` (``"%.6g"``, six significant digits); ``claims.json`` is a list of
    ``{"id", "text", "value", "op", "threshold", "holds", "whose", "status"}`` (and ``"unmet"``
    where a claim's conditions are unmet, :class:`~nctwin.report.claims.Claim`) with sorted keys
    and an indent of 2. Both are written atomically: to a temporary file in the target folder,
    then ``os.replace``.
"""

from __future__ import annotations

import json
from collections.abc import Iterable
from pathlib import Path
from typing import Any, Protocol

import pandas as pd

from .. import paths
from ..cache import atomic_write_text
from .papers import check_simple_name

__all__ = ["FLOAT_FORMAT", "Record", "write_claims", "write_table"]

FLOAT_FORMAT: str = "%.6g"
"""printf-style format of floats in results CSV files and in
:func:`~nctwin.report.display.format_table`."""


class Record(Protocol):
    """What :func:`write_claims` writes: anything with a JSON record, such as a
    :class:`~nctwin.report.claims.Claim`."""

    def to_dict(self) -> dict[str, Any]:
        """The JSON record, with an ``"id"``."""
        ...


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
    return atomic_write_text(folder / f"{check_simple_name(name, 'name')}.csv", text)


def write_claims(stem: str, claims: Iterable[Record], *, results_dir: Path | None = None) -> Path:
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
        Path of the written file: a JSON list of the claims' records
        (:meth:`~nctwin.report.claims.Claim.to_dict`), keys sorted, indent 2, trailing newline.

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
    """``<results>/<stem>``, of ``folder`` or ``paths.results_dir()``."""
    base = paths.results_dir() if folder is None else Path(folder)
    return base / check_simple_name(stem, "stem")
