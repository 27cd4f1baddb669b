r"""Training programs of CAM geometry for Chien, Sencer & Ward (2023): the blends a CAM system's
pocket asks of a control, in G1 lines only.

The paper's training programs (Sec. 3.1, 4.2) have "~2000 blend geometries" each; its test
pocket (Fig. 8) is CAM output: long wall lines that end tangentially on arcs written as short
chords, sharp corners, and reversals where the tool goes into a corner and back. The random
programs of :mod:`nctwin.programs.training` have long lines meeting at random angles; these add
the CAM blends. A program is a chain of *sections*, each a straight line followed by one blend:

* ``"arc"``: a tangent arc (a fillet, a rounded corner of an offset, a chord run of a large
  radius) written as chords within a CAM chordal tolerance, then the next line leaves it
  tangentially (line-arc-line);
* ``"corner"``: a sharp turn (a local blend);
* ``"reversal"``: a turn back by 150-180 degrees (the corner loops and links of a pocket).

The turn of a blend is a right angle (an offset ring's corner, either way) in half the sections
and uniform in :math:`(-\pi, \pi)` in the other half. Every draw takes a seed; nothing uses a
global random state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_int, check_range
from .training import ProgramSpec, _log_uniform, _polyline, _rng, program_text, specs_of

__all__ = [
    "BLEND_KINDS",
    "CHORD_TOL_MM",
    "LINE_MM",
    "RADIUS_MM",
    "BlendSpec",
    "cam_blend_program",
    "cam_blend_specs",
]

#: Kinds of blend and their probabilities.
BLEND_KINDS = {"arc": 0.5, "corner": 0.35, "reversal": 0.15}
#: Length range of the straight lines between blends (mm), log-uniform.
LINE_MM = (0.5, 1000.0)
#: Radius range of the arcs (mm), log-uniform: corner roundings of a tenth of a millimetre to
#: fillets and chord runs of 100 mm.
RADIUS_MM = (0.1, 100.0)
#: Chordal tolerance range of the arcs (mm), log-uniform: what CAM systems are set to.
CHORD_TOL_MM = (0.0005, 0.01)
#: Most chords of one arc.
MAX_CHORDS = 150


def _arc(rng: np.random.Generator, turn: float) -> tuple[np.ndarray, np.ndarray]:
    """Chords of a tangent arc that turns the path by ``turn`` (rad): lengths and the turn at the
    start of each chord (half a chord's angle at the first), shape (n,) each, and the turn left
    for the line after it."""
    radius = _log_uniform(rng, *RADIUS_MM)
    tol = min(_log_uniform(rng, *CHORD_TOL_MM), 0.5 * radius)
    step = 2.0 * math.acos(1.0 - tol / radius)
    n = min(max(1, math.ceil(abs(turn) / step)), MAX_CHORDS)
    phi = turn / n
    lengths = np.full(n, 2.0 * radius * abs(math.sin(0.5 * phi)))
    turns = np.full(n, phi)
    turns[0] = 0.5 * phi
    return lengths, turns, 0.5 * phi


def _sections(rng: np.random.Generator, n_lines: int) -> tuple[np.ndarray, np.ndarray]:
    """Lengths and turns (at the start of each line) of at least ``n_lines`` G-lines."""
    kinds = list(BLEND_KINDS)
    p = list(BLEND_KINDS.values())
    lengths, turns, count, carry = [], [], 0, 0.0
    while count < n_lines:
        lengths.append([_log_uniform(rng, *LINE_MM)])
        turns.append([carry])
        kind = kinds[int(rng.choice(len(kinds), p=p))]
        sign = rng.choice([-1.0, 1.0])
        if kind == "reversal":
            carry = sign * math.radians(rng.uniform(150.0, 180.0))
        else:
            turn = 0.5 * math.pi if rng.random() < 0.5 else rng.uniform(0.0, math.pi)
            carry = sign * turn
        if kind == "arc":
            ln, tn, carry = _arc(rng, carry)
            lengths.append(ln)
            turns.append(tn)
        count += len(lengths[-1]) + (kind == "arc")
    return np.concatenate(lengths)[:n_lines], np.concatenate(turns)[:n_lines]


def cam_blend_program(
    seed: int | np.random.Generator, *, n_lines: int = 2000, feed_mm_s: float, tol_mm: float
) -> str:
    """A training program of CAM blends (see the module docstring).

    Parameters
    ----------
    seed : int or numpy.random.Generator
    n_lines : int
        Number of G1 lines (before points that round onto their predecessor are dropped).
    feed_mm_s, tol_mm : float
        Programmed feed and ``G64 P`` blending tolerance.

    Returns
    -------
    str
        G-code text (:func:`nctwin.programs.training.program_text`).
    """
    check_int("n_lines", n_lines, 2)
    check_range("feed_mm_s", feed_mm_s, 0.0, 1000.0, low_open=True)
    check_range("tol_mm", tol_mm, 0.0, 10.0, low_open=True)
    lengths, turns = _sections(_rng(seed), n_lines)
    return program_text(
        _polyline(lengths, turns), feed_mm_s=feed_mm_s, tol_mm=tol_mm,
        title=f"nctwin CAM-blend training program: F {feed_mm_s:g} mm/s, eps {tol_mm:g} mm",
    )  # fmt: skip


@dataclass(frozen=True)
class BlendSpec(ProgramSpec):
    """A training program of family ``"global"``, ``"mixed"`` (see :class:`ProgramSpec`) or
    ``"cam"`` (:func:`cam_blend_program`)."""

    def text(self) -> str:
        """The program's G-code."""
        if self.family != "cam":
            return super().text()
        return cam_blend_program(
            self.seed, n_lines=self.n_lines, feed_mm_s=self.feed_mm_s, tol_mm=self.tol_mm
        )


def cam_blend_specs(
    seed: int,
    *,
    n_programs: int,
    n_lines: int,
    feed_range_mm_s: tuple[float, float],
    tol_range_mm: tuple[float, float],
    shares: dict[str, float],
) -> list[BlendSpec]:
    """A training set of ``n_programs`` programs, ``shares`` of them of each family (rounded,
    the remainder to the last family); feeds and tolerances uniform in their ranges (rounded to
    1 mm/s and 0.005 mm), each program with its own seed drawn from ``seed``.

    Raises
    ------
    ValueError
        If ``n_programs < 1``, ``n_lines < 2``, a family is unknown or the shares do not sum to 1.
    """
    known = ("global", "mixed", "paper_global", "paper_mixed", "cam")
    if set(shares) - set(known) or not math.isclose(sum(shares.values()), 1.0):
        raise ValueError(f"shares = {shares!r}: families of {', '.join(known)} summing to 1")
    names = list(shares)
    counts = [round(shares[f] * n_programs) for f in names[:-1]]
    counts.append(n_programs - sum(counts))
    families = [f for f, c in zip(names, counts, strict=True) for _ in range(c)]
    return specs_of(seed, families, n_lines, feed_range_mm_s, tol_range_mm, BlendSpec)
