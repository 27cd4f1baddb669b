"""A paper's claims (:class:`Claim`, one checkable statement each) and their report: write
``results/<stem>/claims.json`` and print each claim.

Every chapter ends with one call,

.. code-block:: python

    report_claims(STEM, chapter.claims(...));

where ``chapter.claims`` builds the chapter's :class:`Claim` list from its tables. A failing
claim is reported (``FAILS``), never asserted away. In a notebook, the call also glues the
chapter's status and why (``chapter_status``, ``chapter_status_why``: the Verdicts page's,
:func:`nctwin.report.verdicts.status_of`), which the chapter's opening shows.

The printed line is :data:`LINE` with :data:`VERDICTS` unless a chapter keeps its own (the
chapters were written with slightly different lines, and their checked outputs stay as they
are); ``table=True`` prints the claims as a table instead, one row per :meth:`Claim.to_dict`
record.
"""

from __future__ import annotations

import dataclasses
import math
import operator
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from .conditions import Condition
from .display import format_table
from .results import write_claims
from .verdicts import grouped, status_of

__all__ = [
    "LINE",
    "NOT_TESTED",
    "OPS",
    "VERDICTS",
    "WHOSE",
    "Claim",
    "bootstrap_interval",
    "claims_by_seed",
    "format_claim",
    "report_claims",
    "with_seeds",
]

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

#: The line printed per claim: ``str.format`` fields ``verdict``, ``id``, ``text``, ``value``,
#: ``op`` and ``threshold``.
LINE = "{verdict}  {id}: {value:.2f} {op} {threshold:g}"
#: The verdict words: (claim holds, claim fails). A claim whose conditions are unmet prints
#: :data:`NOT_TESTED` and the unmet conditions' ids after the line.
VERDICTS = ("holds", "FAILS")
NOT_TESTED = "not tested"


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
        :func:`report_claims` from the chapter's conditions).
    seeds_passing, seeds
        For a learned claim judged on an ensemble: how many of the ``seeds`` single networks
        pass the claim on their own ("k of n"); None elsewhere.
    interval
        For a learned claim: a bootstrap interval of ``value`` over the seeds
        (:func:`bootstrap_interval`), ``(low, high)``; None elsewhere.

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


def format_claim(claim: Claim, line: str = LINE, verdicts: tuple[str, str] = VERDICTS) -> str:
    """One claim as a line of text.

    Parameters
    ----------
    claim : Claim
    line : str
        ``str.format`` template with the fields ``verdict``, ``id``, ``text``, ``value``, ``op``
        and ``threshold`` (``value`` and ``threshold`` are floats).
    verdicts : tuple of str
        The word for a claim that holds and for one that fails.

    Returns
    -------
    str
    """
    verdict = NOT_TESTED if claim.unmet else verdicts[0] if claim.holds else verdicts[1]
    text = line.format(verdict=verdict, id=claim.id, text=claim.text, value=claim.value,
                       op=claim.op, threshold=claim.threshold)  # fmt: skip
    if claim.interval is not None:
        text += f"  [interval {claim.interval[0]:.3g} to {claim.interval[1]:.3g}]"
    if claim.seeds is not None:
        text += f"  [{claim.seeds_passing} of {claim.seeds} single networks pass]"
    return text + (f"  [unmet: {grouped(claim.unmet)}]" if claim.unmet else "")


def report_claims(
    stem: str,
    claims: Iterable[Claim],
    *,
    line: str = LINE,
    verdicts: tuple[str, str] = VERDICTS,
    table: bool = False,
    conditions: Iterable[Condition] | None = None,
    results_dir: Path | None = None,
) -> None:
    """Write the claims to ``results/<stem>/claims.json`` and print them.

    Nothing is returned: a notebook's claims cell is this one call, and its only output is the
    printed claims (a returned value would be a second output, which a kernel without input
    history shows even behind a ``;``).

    Parameters
    ----------
    stem : str
        Notebook stem, e.g. ``"chien2023_bilstm"``.
    claims : iterable of Claim
        In the order they are written and printed; ids must be unique.
    line, verdicts : str, tuple of str
        How each claim is printed (:func:`format_claim`).
    table : bool
        Print one table of the claims' records (:func:`~nctwin.report.display.format_table`)
        instead of one line per claim.
    conditions : iterable of Condition, optional
        The chapter's conditions (:func:`~nctwin.report.conditions.report_conditions`): each
        claim's unmet ones (of its ``requires``) make it not tested.
    results_dir : pathlib.Path, optional
        Results folder; default ``paths.results_dir()``.

    Raises
    ------
    ValueError
        If two claims share an id, or a claim requires a condition not among ``conditions``
        (nothing is written).
    """
    met = {c.id: c.met for c in conditions or ()}
    claims = list(claims)
    for c in claims:
        unknown = [r for r in c.requires if r not in met]
        if unknown:
            raise ValueError(f"claim {c.id!r} requires conditions not given: {unknown}")
    claims = [dataclasses.replace(c, unmet=tuple(r for r in c.requires if not met[r]))
              for c in claims]  # fmt: skip
    write_claims(stem, claims, results_dir=results_dir)
    _glue_status(claims)
    if table:
        print(format_table(pd.DataFrame([c.to_dict() for c in claims])))
    else:
        for c in claims:
            print(format_claim(c, line, verdicts))


def _glue_status(claims: list[Claim]) -> None:
    """In a notebook, glue the chapter's status and why (:func:`~nctwin.report.verdicts.
    status_of`) as ``chapter_status`` and ``chapter_status_why``, for the chapter's opening
    (``{glue:text}`chapter_status```); nothing outside a kernel."""
    from IPython import get_ipython

    if get_ipython() is None:
        return
    from myst_nb import glue

    status, why = status_of([c.to_dict() for c in claims])
    glue("chapter_status", status, display=False)
    glue("chapter_status_why", why, display=False)


def claims_by_seed(ensemble: list[Claim], per_seed: dict[int, list[Claim]]) -> pd.DataFrame:
    """Each claim's value and verdict for the ensemble (the rule) beside every seed's own.

    Parameters
    ----------
    ensemble : list of Claim
        A chapter's claims on the mean of the seeds' predictions (the rule).
    per_seed : dict
        Seed -> The same claims, in the same order, of that seed's networks alone.

    Returns
    -------
    pandas.DataFrame
        One row per claim: ``id``, ``op``, ``threshold``, ``ensemble`` (value), ``holds``,
        ``seed_<s>`` (each seed's value), ``seed_min``, ``seed_max``, ``seed_std`` (sample
        standard deviation) and ``seeds_holding`` (how many seeds' own claims hold).
    """
    rows = []
    for k, c in enumerate(ensemble):
        values = np.array([per_seed[s][k].value for s in per_seed], dtype=float)
        by_seed = {f"seed_{s}": v for s, v in zip(per_seed, values, strict=True)}
        rows.append({"id": c.id, "op": c.op, "threshold": c.threshold, "ensemble": c.value,
                     "holds": c.holds, **by_seed,
                     "seed_min": values.min(), "seed_max": values.max(),
                     "seed_std": values.std(ddof=1) if len(values) > 1 else np.nan,
                     "seeds_holding": sum(per_seed[s][k].holds for s in per_seed)})  # fmt: skip
    return pd.DataFrame(rows)


def bootstrap_interval(
    per_seed: np.ndarray,
    statistic: Callable[[np.ndarray], float],
    *,
    level: float = 0.9,
    n_boot: int = 2000,
    seed: int = 0,
) -> tuple[float, float]:
    """Percentile bootstrap interval of an ensemble's statistic over its seeds.

    Parameters
    ----------
    per_seed : ndarray, shape (n, ...)
        Each seed's predictions (row k: seed k's).
    statistic : callable
        Maps an array of rows (shape (n, ...), seeds drawn with replacement) to the claim's
        value for their ensemble, e.g. the error of their mean prediction.
    level : float
        Coverage, in (0, 1).
    n_boot : int
        Resamples.
    seed : int
        Seed of the resampling (``numpy.random.default_rng``).

    Returns
    -------
    tuple of float
        ``(low, high)``: the ``(1 - level) / 2`` and ``(1 + level) / 2`` quantiles of the
        statistic over the resamples.
    """
    per_seed = np.asarray(per_seed, dtype=float)
    draws = np.random.default_rng(seed).integers(0, len(per_seed), (n_boot, len(per_seed)))
    values = np.array([statistic(per_seed[d]) for d in draws])
    low, high = np.quantile(values, [(1 - level) / 2, (1 + level) / 2])
    return float(low), float(high)


def with_seeds(
    claim: Claim, seed_values: Sequence[float], interval: tuple[float, float] | None = None
) -> Claim:
    """``claim`` (judged on an ensemble) with how many single networks pass it, from each seed's
    own value (``seed_values``, one per seed, in the claim's unit), and ``interval``."""
    passing = sum(bool(OPS[claim.op](float(v), claim.threshold)) for v in seed_values
                  if not np.isnan(v))  # fmt: skip
    return dataclasses.replace(claim, seeds_passing=passing, seeds=len(seed_values),
                               interval=interval)  # fmt: skip
