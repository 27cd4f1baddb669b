r"""Training and test programs of Chien, Sencer & Ward (2023, Sec. 3.1 and 4.1).

Two families of *training* programs (Sec. 3.1, Fig. 6), planar, linear G-lines only:

* **Global** programs trigger global blending: every G-line is short, :math:`l_k \in (0, 1)` mm
  (here :data:`GLOBAL_LENGTH_MM`), and the feed direction turns at every junction. The path is a
  chain of *sections*; in each, the direction turns by a section-wide rate (a curve of random
  radius, discretised as CAM systems do) plus a random jitter, and with probability
  :data:`SHARP_SHARE` a junction turns by an angle drawn uniformly in :math:`(-\pi, \pi)`, so the
  corner angles :math:`\theta_k` of the data set cover :math:`(0, \pi)` (the paper's "random
  :math:`\theta_k \in (0, 2\pi)`" direction changes: a turn by :math:`\phi` and by
  :math:`2\pi - \phi` are the same corner).
* **Mixed** programs (75 % local, 25 % global G-lines): global sections as above alternate with
  runs of *local* G-lines of length :math:`l_k \in (0, 1000)` mm and random direction changes in
  :math:`(-\pi, \pi)`. The lengths are log-uniform in :data:`LOCAL_LENGTH_MM` rather than
  uniform, so that lines of a few millimetres (where the corners of both ends interact) are as
  common as lines of hundreds: a uniform draw would make 99 % of them longer than 10 mm. Half
  the local runs leave the curve before them tangentially, as lines meet arcs in real parts.

The families as the paper writes them, ``"paper_global"`` and ``"paper_mixed"``
(:func:`paper_global_program`, :func:`paper_mixed_program`): the same lengths, but the direction
turns by an angle drawn uniformly in :math:`(-\pi, \pi)` (a direction change
:math:`\theta_k \in (0, 2\pi)`) at *every* junction, global and local alike, with no curve and no
tangential exits. Their global lines are a random walk of sub-millimetre steps: half their
junctions turn by more than 90 degrees, where the curve sections above turn by more than 90
degrees at about one junction in forty.

Two *test* contours (Table 1, "toolpath I" and "toolpath II", Fig. 7): closed-free chains of
straight lines, sharp zig-zags (local blends of short lines), and smooth curves discretised into
short chords (global blends), in a fixed random order. Toolpath II has about 6 times the
sections of I, so it takes about 6-7 times as long, as in Table 1.

Every generator takes a :class:`numpy.random.Generator` (or a seed) and returns G-code text
(mm, absolute, ``G64 P<eps>`` for the blending tolerance), which :func:`nctwin.gcode.parse`
reads; nothing uses a global random state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..checks import check_range

__all__ = [
    "GLOBAL_LENGTH_MM",
    "LOCAL_LENGTH_MM",
    "SHARP_SHARE",
    "ProgramSpec",
    "broad_program",
    "contour_program",
    "global_program",
    "mixed_program",
    "paper_contour_program",
    "paper_global_program",
    "paper_mixed_program",
    "program_text",
    "specs_of",
    "training_specs",
]

#: Length range of globally blended G-lines (mm): the paper's (0, 1) mm without lines so short
#: that four decimals would round them to nothing.
GLOBAL_LENGTH_MM = (0.05, 1.0)
#: Length range of locally blended G-lines (mm), drawn log-uniform (paper: (0, 1000) mm).
LOCAL_LENGTH_MM = (0.5, 1000.0)
#: Share of junctions in global sections that turn by a random angle in (-pi, pi).
SHARP_SHARE = 0.05
#: Radius range of the curves of global sections (mm), drawn log-uniform.
CURVE_RADIUS_MM = (1.0, 200.0)
#: G-lines per section (global sections and local runs of mixed programs).
SECTION_LINES = (10, 80)


def _rng(seed: int | np.random.Generator) -> np.random.Generator:
    return seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)


def _log_uniform(rng: np.random.Generator, lo: float, hi: float, size=None):
    return np.exp(rng.uniform(math.log(lo), math.log(hi), size))


def _global_turns(rng: np.random.Generator, lengths_mm: np.ndarray) -> np.ndarray:
    """Direction change at the start of each short G-line of a global section (rad), shape (n,).

    A curve of log-uniform radius ``R`` turns by ``l_k / R`` per line, with a jitter of up to
    the same size; a share :data:`SHARP_SHARE` of the junctions turns by a uniform random angle.
    """
    n = len(lengths_mm)
    radius = _log_uniform(rng, *CURVE_RADIUS_MM) * rng.choice([-1.0, 1.0])
    jitter = rng.uniform(0.0, 1.0) if rng.random() < 0.5 else 0.0
    turns = lengths_mm / radius * (1.0 + jitter * rng.uniform(-1.0, 1.0, n))
    sharp = rng.random(n) < SHARP_SHARE
    turns[sharp] = rng.uniform(-math.pi, math.pi, int(sharp.sum()))
    return turns


def _polyline(lengths_mm: np.ndarray, turns_rad: np.ndarray) -> np.ndarray:
    """End points (n, 2) of a chain of lines from the origin with the given lengths and turns."""
    heading = np.cumsum(turns_rad)
    steps = lengths_mm[:, None] * np.column_stack([np.cos(heading), np.sin(heading)])
    return np.cumsum(steps, axis=0)


def program_text(points_mm: np.ndarray, *, feed_mm_s: float, tol_mm: float, title: str) -> str:
    """G-code of a planar chain of G1 lines from the origin through ``points_mm`` (n, 2).

    Coordinates are written with four decimals; a point that rounds onto its predecessor is
    dropped, so the program has no zero-length line.
    """
    rounded = np.round(np.vstack([[0.0, 0.0], points_mm]), 4)
    keep = np.concatenate([[True], np.any(np.diff(rounded, axis=0) != 0, axis=1)])
    rounded = rounded[keep][1:]
    lines = [f"({title})", "G21 G90 G17", f"G64 P{tol_mm:g}", f"G1 F{feed_mm_s * 60:g}"]
    lines += [f"X{x:.4f} Y{y:.4f}" for x, y in rounded]
    lines.append("M30")
    return "\n".join(lines) + "\n"


def _global_section(
    rng: np.random.Generator,
    n: int,
    length_mm: tuple[float, float] | None = None,
    literal: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    r"""Short lines on a curve: in half the sections of random lengths, in the other half of one
    length (a CAM system's constant chord). Lengths are uniform in :data:`GLOBAL_LENGTH_MM`, or
    log-uniform in ``length_mm`` where given. ``literal``: the paper's lines, lengths uniform in
    :data:`GLOBAL_LENGTH_MM` and a uniform turn in :math:`(-\pi, \pi)` at every junction."""
    if literal:
        return rng.uniform(*GLOBAL_LENGTH_MM, n), rng.uniform(-math.pi, math.pi, n)

    def draw(size=None):
        if length_mm is None:
            return rng.uniform(*GLOBAL_LENGTH_MM, size)
        return _log_uniform(rng, *length_mm, size)

    lengths = draw(n) if rng.random() < 0.5 else np.full(n, draw())
    return lengths, _global_turns(rng, lengths)


def _local_section(
    rng: np.random.Generator, n: int, literal: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Long lines with random direction changes; in half the runs the first line leaves the
    section before it tangentially (a line meeting a curve, as in pockets and contours), unless
    ``literal`` (the paper's random direction changes only)."""
    turns = rng.uniform(-math.pi, math.pi, n)
    if not literal and rng.random() < 0.5:
        turns[0] = 0.0
    return _log_uniform(rng, *LOCAL_LENGTH_MM, n), turns


def _sections(
    rng: np.random.Generator,
    n_lines: int,
    local_share: float,
    global_length_mm: tuple[float, float] | None = None,
    literal: bool = False,
):
    """Lengths and turns of ``n_lines`` G-lines: sections of 10-80 lines, local with
    probability ``local_share`` (by G-line count, on average); see :func:`_global_section` for
    ``global_length_mm`` and ``literal``."""
    lengths, turns, count = [], [], 0
    while count < n_lines:
        n = min(int(rng.integers(*SECTION_LINES, endpoint=True)), n_lines - count)
        local = rng.random() < local_share
        if local:
            ln, tn = _local_section(rng, n, literal)
        else:
            ln, tn = _global_section(rng, n, global_length_mm, literal)
        lengths.append(ln)
        turns.append(tn)
        count += n
    return np.concatenate(lengths), np.concatenate(turns)


def global_program(
    seed: int | np.random.Generator,
    *,
    n_lines: int = 1000,
    feed_mm_s: float,
    tol_mm: float,
    literal: bool = False,
) -> str:
    """A "global blending" training program (Sec. 3.1, Fig. 6a): short lines on random curves,
    or with ``literal`` the paper's random turn at every junction (:func:`paper_global_program`).

    Parameters
    ----------
    seed : int or numpy.random.Generator
    n_lines : int
        Number of G1 lines.
    feed_mm_s, tol_mm : float
        Programmed feed and ``G64 P`` blending tolerance.
    literal : bool
        The paper's lines (see the module docstring).

    Returns
    -------
    str
        G-code text.
    """
    rng = _rng(seed)
    lengths, turns = _sections(rng, n_lines, local_share=0.0, literal=literal)
    kind = "paper global" if literal else "global"
    return program_text(
        _polyline(lengths, turns), feed_mm_s=feed_mm_s, tol_mm=tol_mm,
        title=f"nctwin {kind} training program: F {feed_mm_s:g} mm/s, eps {tol_mm:g} mm",
    )  # fmt: skip


def mixed_program(
    seed: int | np.random.Generator,
    *,
    n_lines: int = 1000,
    feed_mm_s: float,
    tol_mm: float,
    local_share: float = 0.75,
    literal: bool = False,
) -> str:
    """A "mixed" training program (Sec. 3.1, Fig. 6b): 75 % local, 25 % global G-lines.

    Parameters
    ----------
    seed : int or numpy.random.Generator
    n_lines : int
        Number of G1 lines.
    feed_mm_s, tol_mm : float
        Programmed feed and ``G64 P`` blending tolerance.
    local_share : float
        Expected share of G-lines in local sections.
    literal : bool
        The paper's lines (see the module docstring).

    Returns
    -------
    str
        G-code text.
    """
    check_range("local_share", local_share, 0.0, 1.0)
    rng = _rng(seed)
    lengths, turns = _sections(rng, n_lines, local_share=local_share, literal=literal)
    kind = "paper mixed" if literal else "mixed"
    return program_text(
        _polyline(lengths, turns), feed_mm_s=feed_mm_s, tol_mm=tol_mm,
        title=f"nctwin {kind} training program: F {feed_mm_s:g} mm/s, eps {tol_mm:g} mm",
    )  # fmt: skip


def paper_global_program(
    seed: int | np.random.Generator, *, n_lines: int = 1000, feed_mm_s: float, tol_mm: float
) -> str:
    """The paper's "global" family as written (Sec. 3.1): lines of (0, 1) mm, a uniform turn at
    every junction (:func:`global_program` with ``literal=True``)."""
    return global_program(seed, n_lines=n_lines, feed_mm_s=feed_mm_s, tol_mm=tol_mm, literal=True)


def paper_mixed_program(
    seed: int | np.random.Generator, *, n_lines: int = 1000, feed_mm_s: float, tol_mm: float
) -> str:
    """The paper's "mixed" family as written (Sec. 3.1): 75 % local lines, 25 % global, a uniform
    turn at every junction (:func:`mixed_program` with ``literal=True``)."""
    return mixed_program(seed, n_lines=n_lines, feed_mm_s=feed_mm_s, tol_mm=tol_mm, literal=True)


@dataclass(frozen=True)
class ProgramSpec:
    """One training program: its family (``"global"``, ``"mixed"``, ``"paper_global"``,
    ``"paper_mixed"``), size, feed, tolerance and seed."""

    family: str
    n_lines: int
    feed_mm_s: float
    tol_mm: float
    seed: int

    def text(self) -> str:
        """The program's G-code."""
        make = {"global": global_program, "mixed": mixed_program,
                "paper_global": paper_global_program, "paper_mixed": paper_mixed_program}[
            self.family]  # fmt: skip
        return make(self.seed, n_lines=self.n_lines, feed_mm_s=self.feed_mm_s, tol_mm=self.tol_mm)


def training_specs(
    seed: int,
    *,
    n_programs: int,
    n_lines: int,
    feed_range_mm_s: tuple[float, float],
    tol_range_mm: tuple[float, float],
    mixed_share: float = 0.5,
) -> list[ProgramSpec]:
    """The training set: ``n_programs`` programs, a share ``mixed_share`` of them mixed.

    Feeds and tolerances are uniform in their ranges (rounded to 1 mm/s and 0.005 mm, as a
    programmer would type them); each program gets its own seed from ``seed``.
    """
    n_mixed = round(mixed_share * n_programs)
    families = ["mixed"] * n_mixed + ["global"] * (n_programs - n_mixed)
    return specs_of(seed, families, n_lines, feed_range_mm_s, tol_range_mm)


def specs_of(
    seed: int,
    families: list[str],
    n_lines: int,
    feed_range_mm_s: tuple[float, float],
    tol_range_mm: tuple[float, float],
    spec: type[ProgramSpec] = ProgramSpec,
) -> list[ProgramSpec]:
    """One ``spec`` (:class:`ProgramSpec` or a subclass that knows more families) per entry of
    ``families``: feeds and tolerances uniform in their ranges (rounded to 1 mm/s and 0.005 mm,
    as a programmer would type them), each program with its own seed drawn from ``seed``."""
    n_programs = len(families)
    if n_programs < 1 or n_lines < 2:
        raise ValueError(f"n_programs = {n_programs}, n_lines = {n_lines}: need >= 1 and >= 2")
    rng = np.random.default_rng(seed)
    feeds = np.round(rng.uniform(*feed_range_mm_s, n_programs))
    tols = np.round(rng.uniform(*tol_range_mm, n_programs) / 0.005) * 0.005
    seeds = rng.integers(0, 2**63 - 1, n_programs)
    return [
        spec(f, n_lines, float(v), round(float(e), 4), int(s))
        for f, v, e, s in zip(families, feeds, tols, seeds, strict=True)
    ]


def broad_program(
    seed: int | np.random.Generator,
    *,
    n_lines: int,
    feed_range_mm_s: tuple[float, float],
    tol_range_mm: tuple[float, float],
    no_tol_share: float,
    naive_share: float,
    global_length_mm: tuple[float, float],
    max_tilt_rad: float,
    max_time_s: float,
) -> str:
    """A training program beyond paper 1's ranges, for a machine that runs other people's programs.

    Paper 1's G-lines (sections as in :func:`mixed_program`, 25 % local) with

    * the feed log-uniform in ``feed_range_mm_s`` and the ``G64 P`` tolerance log-uniform in
      ``tol_range_mm``, or, with probability ``no_tol_share``, a plain ``G64`` (no tolerance);
      with probability ``naive_share`` the ``G64 P`` has no ``Q`` (on LinuxCNC: Q = P, which
      merges nearly collinear lines), else ``Q0``;
    * the short lines of global sections log-uniform in ``global_length_mm``;
    * the plane tilted about the X axis by a uniform angle in ``[0, max_tilt_rad]``, so that
      lines move the Z axis too (3D surfacing);
    * the chain cut after ``max_time_s`` of programmed (CAM) time, so that slow feeds do not
      make hour-long programs.

    Returns
    -------
    str
        G-code text: ``G21 G90 G17``, ``G64 P<eps> Q0``, ``G64 P<eps>`` or ``G64``, ``G1 F``,
        one line per point with X, Y and Z.
    """
    rng = _rng(seed)
    feed = float(np.round(_log_uniform(rng, *feed_range_mm_s), 1))
    tol = (
        None
        if rng.random() < no_tol_share
        else float(np.round(_log_uniform(rng, *tol_range_mm), 4))
    )
    naive = rng.random() < naive_share
    tilt = rng.uniform(0.0, max_tilt_rad)
    lengths, turns = _sections(rng, n_lines, 0.25, global_length_mm)
    keep = np.cumsum(lengths) / feed <= max_time_s
    keep[0] = True
    xy = _polyline(lengths[keep], turns[keep])
    pts = np.column_stack([xy[:, 0], xy[:, 1] * math.cos(tilt), xy[:, 1] * math.sin(tilt)])
    rounded = np.round(np.vstack([np.zeros(3), pts]), 4)
    moved = np.concatenate([[True], np.any(np.diff(rounded, axis=0) != 0, axis=1)])
    g64 = "G64" if tol is None else f"G64 P{tol:g}" + ("" if naive else " Q0")
    tol_text = "none" if tol is None else f"{tol:g} mm"
    lines = [
        f"(nctwin broad training program: F {feed:g} mm/s, eps {tol_text}, "
        f"tilt {math.degrees(tilt):.1f} deg)",
        "G21 G90 G17",
        g64,
        f"G1 F{feed * 60:g}",
    ]
    lines += [f"X{x:.4f} Y{y:.4f} Z{z:.4f}" for x, y, z in rounded[moved][1:]]
    lines.append("M30")
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------------------------------
# Test contours (Table 1, toolpaths I and II)

#: Sections of test toolpaths I and II (II takes 6-7 times as long as I, as in Table 1).
TEST_SECTIONS = {"I": 42, "II": 250}
#: Seeds of the test contours (fixed: the contours are part of the chapter, like the paper's).
TEST_SEEDS = {"I": 1001, "II": 1002}
#: Zig-zag share of the paper's toolpaths I and II (:func:`paper_contour_program`), fixed by
#: CAM's error on Table 1's four rows of each on ``paper1_sim``: the share, on a grid of 0.01 in
#: [0, 0.40], whose largest deviation from the paper's rows is smallest (the smallest on a tie)
#: (:func:`nctwin.chapters.chien2023_calibrate.zigzag_share_rows`): I 3.6 points (CAM's error
#: 29.5, 25.4, 37.2, 32.6 % at 75 and 92 mm/s by 0.3 and 0.4 mm; the paper's 29, 29, 34, 34 %),
#: II 4.0 points (28.9, 25.2, 36.0, 32.0 %; the paper's 28, 27, 32, 31 %).
PAPER_ZIGZAG_SHARE = {"I": 0.11, "II": 0.06}


def _test_section(
    rng: np.random.Generator, zigzag_share: float = 0.35
) -> tuple[np.ndarray, np.ndarray]:
    """One section of a test contour: a sharp zig-zag with probability ``zigzag_share``, else a
    straight or a smooth curve in the ratio 25 : 40."""
    rest = 1.0 - zigzag_share
    p = [rest * 25 / 65, zigzag_share, rest * 40 / 65]
    kind = rng.choice(["straight", "zigzag", "curve"], p=p)
    if kind == "straight":
        n = int(rng.integers(1, 4))
        return rng.uniform(15.0, 60.0, n), rng.uniform(-0.5, 0.5, n) * math.pi
    if kind == "zigzag":
        n = int(rng.integers(6, 20))
        legs = rng.uniform(1.0, 8.0) * rng.uniform(0.7, 1.3, n)
        angle = rng.uniform(0.4, 0.85) * math.pi
        return legs, angle * (-1.0) ** np.arange(n)
    radius = _log_uniform(rng, 2.0, 60.0)
    sweep = rng.uniform(0.5, 1.5) * math.pi * rng.choice([-1.0, 1.0])
    chord = rng.uniform(0.3, 1.0)
    n = max(3, math.ceil(abs(sweep) * radius / chord))
    lengths = np.full(n, abs(sweep) * radius / n)
    turns = np.full(n, sweep / n)
    turns[0] = rng.uniform(-0.25, 0.25) * math.pi
    return lengths, turns


def contour_program(
    name: str, *, feed_mm_s: float, tol_mm: float, zigzag_share: float = 0.35
) -> str:
    """Test toolpath I or II of Table 1: a complex planar contour with sharp and smooth sections.

    Parameters
    ----------
    name : {"I", "II"}
    feed_mm_s, tol_mm : float
        Programmed feed and ``G64 P`` blending tolerance.
    zigzag_share : float
        Probability of a zig-zag section, in [0, 1].

    Returns
    -------
    str
        G-code text.
    """
    if name not in TEST_SECTIONS:
        raise ValueError(f"name = {name!r} is unknown: allowed {', '.join(TEST_SECTIONS)}")
    check_range("zigzag_share", zigzag_share, 0.0, 1.0)
    rng = np.random.default_rng(TEST_SEEDS[name])
    parts = [_test_section(rng, zigzag_share) for _ in range(TEST_SECTIONS[name])]
    lengths = np.concatenate([p[0] for p in parts])
    turns = np.concatenate([p[1] for p in parts])
    return program_text(
        _polyline(lengths, turns), feed_mm_s=feed_mm_s, tol_mm=tol_mm,
        title=f"nctwin test toolpath {name}: F {feed_mm_s:g} mm/s, eps {tol_mm:g} mm",
    )  # fmt: skip


def paper_contour_program(name: str, *, feed_mm_s: float, tol_mm: float) -> str:
    """Toolpath I or II of the paper's Table 1: :func:`contour_program` with the zig-zag share
    of :data:`PAPER_ZIGZAG_SHARE`."""
    if name not in PAPER_ZIGZAG_SHARE:
        raise ValueError(f"name = {name!r} is unknown: allowed {', '.join(PAPER_ZIGZAG_SHARE)}")
    return contour_program(
        name, feed_mm_s=feed_mm_s, tol_mm=tol_mm, zigzag_share=PAPER_ZIGZAG_SHARE[name]
    )
