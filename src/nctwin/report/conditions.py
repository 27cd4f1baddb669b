r"""A paper's conditions: what its experiment was run under, ours beside it, and whether ours
meets it.

A claim holds or fails only under the paper's conditions: the size of its parts, its line
counts, feeds and tolerances, its sampling rate, its amount of data, CAM's error on its rows.
Each chapter writes them to ``results/<stem>/conditions.csv`` before any method runs
(:func:`report_conditions`), with the tolerance stated before looking, and names, in each claim,
the conditions it is tested under (:attr:`Claim.requires <nctwin.report.claims.Claim.requires>`).
A claim whose conditions are unmet is *not tested*: it neither holds nor fails
(:func:`nctwin.report.claims.report_claims`).

A condition is met when ours lies within ``[low, high]``: bounds given directly, or from the
paper's value and a relative tolerance, :math:`|x - p| \le \text{tol}\,|p| / 100`. A
condition the chapter cannot meet says why (:attr:`Condition.why`): what the paper does not
publish, or what the truth cannot give; ``conditions.csv`` holds it beside the unmet row.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from .display import show
from .results import write_table

__all__ = ["CONDITION_COLUMNS", "Condition", "conditions_table", "report_conditions"]

#: Columns of ``conditions.csv``.
CONDITION_COLUMNS = ("id", "text", "paper", "ours", "unit", "low", "high", "met", "why")


@dataclass(frozen=True)
class Condition:
    """One condition of a paper's experiment.

    Parameters
    ----------
    id : str
        Short stable identifier, named by the claims that require it.
    text : str
        The condition in words, citing where the paper gives it.
    paper : float
        The paper's value (read from ``data/papers/``); NaN where the paper gives a range only.
    ours : float
        Ours; NaN: not measured, which does not meet the condition.
    unit : str
    tol_pct : float, optional
        Relative tolerance around ``paper``, in percent, stated before looking.
    low, high : float, optional
        Bounds instead of a tolerance (either may be infinite).
    why : str, optional
        Why ours cannot meet the condition from what the paper publishes (or what the truth
        gives), with the evidence; written and shown only where the condition is unmet.

    Raises
    ------
    ValueError
        If neither a tolerance (with a finite ``paper``) nor a bound is given, or both are.
    """

    id: str
    text: str
    paper: float
    ours: float
    unit: str = ""
    tol_pct: float | None = None
    low: float | None = None
    high: float | None = None
    why: str = ""

    def __post_init__(self) -> None:
        bounds = self.low is not None or self.high is not None
        if (self.tol_pct is None) == (not bounds):
            raise ValueError(f"condition {self.id!r}: give tol_pct or low/high, not both or none")
        if self.tol_pct is not None and (not math.isfinite(self.paper) or self.tol_pct < 0):
            raise ValueError(
                f"condition {self.id!r}: tol_pct = {self.tol_pct!r} needs a finite paper value "
                "and a tolerance >= 0"
            )
        object.__setattr__(self, "paper", float(self.paper))
        object.__setattr__(self, "ours", float(self.ours))

    @property
    def bounds(self) -> tuple[float, float]:
        """``(low, high)``: the range ours must lie in."""
        if self.tol_pct is not None:
            half = abs(self.paper) * self.tol_pct / 100
            return self.paper - half, self.paper + half
        low = -math.inf if self.low is None else float(self.low)
        return low, math.inf if self.high is None else float(self.high)

    @property
    def met(self) -> bool:
        """Whether ours lies within :attr:`bounds` (False where ours is NaN)."""
        low, high = self.bounds
        return bool(low <= self.ours <= high)


def conditions_table(conditions: Iterable[Condition]) -> pd.DataFrame:
    """The conditions as ``conditions.csv`` holds them (:data:`CONDITION_COLUMNS`)."""
    rows = [{"id": c.id, "text": c.text, "paper": c.paper, "ours": c.ours, "unit": c.unit,
             "low": c.bounds[0], "high": c.bounds[1], "met": c.met,
             "why": "" if c.met else c.why}
            for c in conditions]  # fmt: skip
    return pd.DataFrame(rows, columns=list(CONDITION_COLUMNS))


def report_conditions(
    stem: str, conditions: Iterable[Condition], *, results_dir: Path | None = None
) -> list[Condition]:
    """Write ``results/<stem>/conditions.csv`` and show it, the unmet conditions' reasons as
    footnotes; return the conditions (for :func:`nctwin.report.claims.report_claims`).

    Raises
    ------
    ValueError
        If two conditions share an id (nothing is written).
    """
    conditions = list(conditions)
    ids = [c.id for c in conditions]
    if len(set(ids)) != len(ids):
        raise ValueError(f"condition ids repeat: {sorted({i for i in ids if ids.count(i) > 1})}")
    table = conditions_table(conditions)
    write_table(stem, "conditions", table, results_dir=results_dir)
    show(table[["text", "paper", "ours", "unit", "low", "high", "met", "why"]], notes="why")
    return conditions
