"""An ISO 10791-7-style finishing test piece for a 3-axis machining centre, as real G-code.

ISO 10791-7 defines finishing test pieces whose contours (a square, a diamond, a circle, an
inclined square, a bore) show how a machine tool follows straight lines, arcs and corners. Lee et
al. 2022 (JKSPE 39(7), Sec. 3, Fig. 10) validate their cycle-time estimate on such a program (over
30 minutes, 2169 s measured). The standard's drawing is not reproduced here; this generator writes
a program *in its style*, with the dimensions of the small (160 mm) test piece:

======================  =============================================  ==================
feature (top to bottom)  geometry (part coordinates, origin at centre)  how it is written
======================  =============================================  ==================
circle boss              diameter 108 mm                                four G2 quadrants
diamond                  square of side 110 mm turned 45 degrees        G1 edges, G2 corners
square                   160 mm x 160 mm                                G1 edges, G2 corners
inclined square          170 mm x 170 mm turned 3 degrees               G1 edges, G2 corners
central bore             diameter 30 mm                                 72 G1 chords (CAM-style)
======================  =============================================  ==================

Every feature is finished in ``passes`` depth passes of ``pass_depth_mm``; the outer contours are
offset by the tool radius (climb milling, clockwise, with corner arcs of the tool radius), the
bore is traversed counter-clockwise. Each pass is: rapid to the safe height, rapid to the approach
point, rapid down to 1 mm above the pass, plunge at ``plunge_feed_mm_min``, lead-in, contour and
lead-out at the constant finishing feed ``feed_mm_min``; the bore ends each pass with a dwell
(G04). The shipped program runs the sequence once, its natural length (about 7.5 minutes on the
paper's testbed parameters): the paper's own program ran 36 minutes, but its drawing and pass plan
are not published, and repeating the sequence only multiplies every time by the same factor.
``repeats`` > 1 repeats the sequence. Nothing is random. The program uses Fanuc conventions
(F in mm/min, ``G04 X`` in seconds) that :func:`nctwin.parse` reads as they are.

Regenerate the shipped file with ``python -m nctwin.programs.iso10791``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..checks import check_int, check_range
from ..gcode import parse
from ..paths import data_dir
from ..toolpath import Toolpath

__all__ = [
    "TEST_PIECE_FILE",
    "TestPieceParams",
    "shipped_test_piece_path",
    "test_piece",
    "test_piece_program",
    "write_test_piece",
]

#: File name of the shipped program in ``data/programs/``.
TEST_PIECE_FILE = "iso10791_7_finishing_test_piece.nc"


@dataclass(frozen=True)
class TestPieceParams:
    """Settings of the test-piece program.

    Parameters
    ----------
    feed_mm_min : float
        Finishing feed of every contour (constant).
    plunge_feed_mm_min : float
        Feed of the plunges to each pass depth.
    tool_radius_mm : float
        End-mill radius; outer contours are offset by it.
    pass_depth_mm : float
        Depth of one finishing pass.
    passes : int
        Depth passes per feature.
    repeats : int
        Repetitions of the whole sequence.
    safe_z_mm : float
        Height of the rapids between features.
    dwell_s : float
        Dwell at the end of each bore pass.
    bore_segments : int
        Chords of the bore's polygon.
    """

    __test__ = False  # not a pytest test class

    feed_mm_min: float = 1000.0
    plunge_feed_mm_min: float = 300.0
    tool_radius_mm: float = 5.0
    pass_depth_mm: float = 2.0
    passes: int = 3
    repeats: int = 1
    safe_z_mm: float = 5.0
    dwell_s: float = 0.5
    bore_segments: int = 72

    def __post_init__(self) -> None:
        for name in ("feed_mm_min", "plunge_feed_mm_min", "tool_radius_mm", "pass_depth_mm",
                     "safe_z_mm"):  # fmt: skip
            check_range(name, getattr(self, name), 0.0, math.inf, low_open=True, high_open=True)
        check_range("dwell_s", self.dwell_s, 0.0, math.inf, high_open=True)
        for name, lo in (("passes", 1), ("repeats", 1), ("bore_segments", 8)):
            check_int(name, getattr(self, name), lo)
        if self.tool_radius_mm >= 15.0:
            raise ValueError(
                f"tool_radius_mm = {self.tool_radius_mm!r} is out of range: allowed (0, 15) "
                "(the bore has a radius of 15 mm)"
            )


def _f(x: float) -> str:
    """A coordinate with 4 decimals, no negative zero."""
    s = f"{x:.4f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _square(side_mm: float, angle_deg: float) -> np.ndarray:
    """Vertices of a square centred at the origin, clockwise from the top-left; shape (4, 3)."""
    h = side_mm / 2.0
    v = np.array([[-h, h], [h, h], [h, -h], [-h, -h]])
    a = math.radians(angle_deg)
    rot = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    return v @ rot.T


def _polygon_pass(v: np.ndarray, r: float, z: float, p: TestPieceParams) -> list[str]:
    """One clockwise pass around the convex polygon ``v`` (clockwise vertices, shape (n, 2))
    offset outwards by ``r``, with straight lead-in/out from 3 r outside the first edge."""
    n = len(v)
    u = np.roll(v, -1, axis=0) - v
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    normal = np.stack([-u[:, 1], u[:, 0]], axis=1)  # outward for clockwise traversal
    mid = 0.5 * (v[0] + v[1]) + r * normal[0]
    approach = mid + 3.0 * r * normal[0]
    out = _approach(approach, z, p)
    out.append(f"G01 X{_f(mid[0])} Y{_f(mid[1])} F{_f(p.feed_mm_min)}")
    for i in range(n):
        j = (i + 1) % n
        a = v[j] + r * normal[i]
        b = v[j] + r * normal[j]
        out.append(f"G01 X{_f(a[0])} Y{_f(a[1])}")
        out.append(f"G02 X{_f(b[0])} Y{_f(b[1])} I{_f(v[j][0] - a[0])} J{_f(v[j][1] - a[1])}")
    out.append(f"G01 X{_f(mid[0])} Y{_f(mid[1])}")
    out.append(f"G01 X{_f(approach[0])} Y{_f(approach[1])}")
    out.append(f"G00 Z{_f(p.safe_z_mm)}")
    return out


def _approach(xy: np.ndarray, z: float, p: TestPieceParams) -> list[str]:
    return [
        f"G00 X{_f(xy[0])} Y{_f(xy[1])}",
        f"G00 Z{_f(z + 1.0)}",
        f"G01 Z{_f(z)} F{_f(p.plunge_feed_mm_min)}",
    ]


def _circle_pass(radius: float, r: float, z: float, p: TestPieceParams) -> list[str]:
    """One clockwise pass around a circular boss of ``radius``: four G2 quadrants."""
    rc = radius + r
    approach = np.array([0.0, rc + 3.0 * r])
    out = _approach(approach, z, p)
    out.append(f"G01 Y{_f(rc)} F{_f(p.feed_mm_min)}")
    for ang in (0.0, -90.0, -180.0, -270.0):  # from 90 deg clockwise by quadrants
        a = math.radians(90.0 + ang)
        b = math.radians(ang)
        sx, sy = rc * math.cos(a), rc * math.sin(a)
        out.append(f"G02 X{_f(rc * math.cos(b))} Y{_f(rc * math.sin(b))} I{_f(-sx)} J{_f(-sy)}")
    out.append(f"G01 Y{_f(approach[1])}")
    out.append(f"G00 Z{_f(p.safe_z_mm)}")
    return out


def _bore_pass(radius: float, r: float, z: float, p: TestPieceParams) -> list[str]:
    """One counter-clockwise pass inside a bore, as ``bore_segments`` chords, then a dwell."""
    rb = radius - r
    out = _approach(np.zeros(2), z, p)
    ang = np.linspace(0.0, 2.0 * np.pi, p.bore_segments + 1)
    out.append(f"G01 X{_f(rb)} Y0 F{_f(p.feed_mm_min)}")
    out += [f"G01 X{_f(rb * math.cos(a))} Y{_f(rb * math.sin(a))}" for a in ang[1:]]
    out.append("G01 X0 Y0")
    if p.dwell_s > 0:
        out.append(f"G04 X{_f(p.dwell_s)}")
    out.append(f"G00 Z{_f(p.safe_z_mm)}")
    return out


def test_piece_program(params: TestPieceParams | None = None) -> str:
    """The test-piece program as G-code text (see the module docstring).

    Parameters
    ----------
    params : TestPieceParams, optional
        Default: ``TestPieceParams()`` (the shipped program).

    Returns
    -------
    str
        The program, ending with ``M30``.
    """
    p = TestPieceParams() if params is None else params
    r = p.tool_radius_mm
    head = [
        "%",
        "(ISO 10791-7-STYLE FINISHING TEST PIECE, WRITTEN BY NCTWIN.PROGRAMS.ISO10791)",
        "(" + ", ".join(f"{k}={v}" for k, v in asdict(p).items()) + ")",
        "G21 G90 G17 G40 G49 G80 G94",
        "M03 S8000",
        f"G00 Z{_f(p.safe_z_mm)}",
    ]
    depths = [-(i + 1) * p.pass_depth_mm for i in range(p.passes)]
    step = p.passes * p.pass_depth_mm
    body: list[str] = []
    for rep in range(p.repeats):
        body.append(f"(REPETITION {rep + 1} OF {p.repeats})")
        body.append("(CIRCLE BOSS D108)")
        for z in depths:
            body += _circle_pass(54.0, r, z, p)
        body.append("(DIAMOND 110 AT 45 DEG)")
        for z in depths:
            body += _polygon_pass(_square(110.0, 45.0), r, z - step, p)
        body.append("(SQUARE 160)")
        for z in depths:
            body += _polygon_pass(_square(160.0, 0.0), r, z - 2 * step, p)
        body.append("(INCLINED SQUARE 170 AT 3 DEG)")
        for z in depths:
            body += _polygon_pass(_square(170.0, 3.0), r, z - 3 * step, p)
        body.append("(CENTRAL BORE D30)")
        for z in depths:
            body += _bore_pass(15.0, r, z, p)
    tail = ["G00 Z50.", "G00 X0 Y0", "M05", "M30", "%"]
    return "\n".join(head + body + tail) + "\n"


def test_piece(params: TestPieceParams | None = None) -> Toolpath:
    """The test-piece program as a :class:`~nctwin.toolpath.Toolpath` (parsed from its text)."""
    return parse(test_piece_program(params), source=TEST_PIECE_FILE)


def shipped_test_piece_path() -> Path:
    """Path of the shipped program, ``data/programs/iso10791_7_finishing_test_piece.nc``."""
    return data_dir() / "programs" / TEST_PIECE_FILE


def write_test_piece(path: str | Path | None = None, params: TestPieceParams | None = None) -> Path:
    """Write the program to ``path`` (default :func:`shipped_test_piece_path`) atomically."""
    target = shipped_test_piece_path() if path is None else Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.name}.tmp")
    tmp.write_text(test_piece_program(params), encoding="utf-8", newline="\n")
    tmp.replace(target)
    return target


if __name__ == "__main__":
    print(write_test_piece())
