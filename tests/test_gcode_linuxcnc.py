"""The native reader against LinuxCNC's own interpreter.

LinuxCNC's preview module (``gcode``, from linuxcnc-uspace, for /usr/bin/python3) runs a program
through rs274ngc and calls back for every canonical move. The moves of canned cycles, G92
offsets, dwells before motion and arcs of several turns must be the blocks nctwin reads: same
kinds, lines, end points, arc centres and turns. Skipped where that module is absent
(``make linuxcnc`` installs it).
"""

from __future__ import annotations

import json
import os
import subprocess

import numpy as np
import pytest

from nctwin import GCodeError, MotionKind, parse
from nctwin.toolpath import PLANE_AXES

PYTHON = "/usr/bin/python3"

#: Runs programs (a JSON list on stdin) through LinuxCNC's interpreter in a metric setup and
#: prints, per program, the moves (mm, G92 offsets added as LinuxCNC's canon adds them) and
#: the error (LinuxCNC's line and message) if any.
ORACLE = r"""
import json, os, sys, tempfile
import gcode

class Canon:
    def __init__(self, var):
        self.parameter_file = var
        self.moves, self.g92, self.lineno, self.plane = [], (0.0, 0.0, 0.0), 0, 1
    def next_line(self, state): self.lineno = state.sequence_number
    def get_external_length_units(self): return 1.0
    def get_external_angular_units(self): return 1.0
    def get_axis_mask(self): return 7
    def get_block_delete(self): return 0
    def get_tool(self, pocket): return (-1,) + (0.0,) * 12 + (0,)
    def set_g92_offset(self, x, y, z, *rest): self.g92 = (x, y, z)
    def set_plane(self, plane): self.plane = plane
    def move(self, kind, *xyz):
        self.moves.append([kind, self.lineno, [25.4 * (v + o) for v, o in zip(xyz, self.g92)]])
    def straight_traverse(self, x, y, z, *rest): self.move("rapid", x, y, z)
    def straight_feed(self, x, y, z, *rest): self.move("feed", x, y, z)
    def dwell(self, t): self.moves.append(["dwell", self.lineno, t])
    def arc_feed(self, e1, e2, c1, c2, turns, e3, *rest):
        o = [self.g92[a] for a in {1: (0, 1, 2), 2: (1, 2, 0), 3: (2, 0, 1)}[self.plane]]
        v = [25.4 * x for x in (e1 + o[0], e2 + o[1], c1 + o[0], c2 + o[1], e3 + o[2])]
        self.moves.append(["arc", self.lineno, v + [turns]])
    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        return lambda *args: None

folder = tempfile.mkdtemp()
var = os.path.join(folder, "rs274ngc.var")
open(var, "w").close()
out = []
for i, text in enumerate(json.load(sys.stdin)):
    path = os.path.join(folder, f"p{i}.ngc")
    with open(path, "w") as f:
        f.write(text + "\nM2\n")
    canon = Canon(var)
    result, line = gcode.parse(path, canon, "G21", "")
    error = None if result <= gcode.MIN_ERROR else [line, gcode.strerror(result)]
    out.append({"moves": canon.moves, "error": error})
print("@@" + json.dumps(out))
"""


@pytest.fixture(scope="module")
def linuxcnc_interpreter():
    """Run programs through LinuxCNC's interpreter; skip (or fail where
    ``NCTWIN_REQUIRE_LINUXCNC=1``) if its preview module is missing."""
    ok = os.path.exists(PYTHON) and (
        subprocess.run([PYTHON, "-c", "import gcode"], capture_output=True).returncode == 0
    )
    if not ok:
        if os.environ.get("NCTWIN_REQUIRE_LINUXCNC") == "1":
            pytest.fail("NCTWIN_REQUIRE_LINUXCNC=1 but LinuxCNC's gcode module is missing")
        pytest.skip("LinuxCNC's gcode module is missing: run `make linuxcnc`")

    def run(texts: list[str]) -> list[dict]:
        out = subprocess.run(
            [PYTHON, "-c", ORACLE], input=json.dumps(texts), capture_output=True, text=True
        ).stdout
        return json.loads(out.split("@@")[-1])

    return run


def _moves(text: str) -> list:
    """nctwin's blocks as LinuxCNC's moves: the turns of an arc on one line are one move."""
    tp = parse(text)
    names = {MotionKind.RAPID: "rapid", MotionKind.LINEAR: "feed"}
    out, k = [], 0
    while k < len(tp):
        kind, line = tp.kind[k], int(tp.line[k])
        if kind == MotionKind.DWELL:
            out.append(["dwell", line, float(tp.dwell_s[k])])
        elif kind in names:
            out.append([names[kind], line, tp.end_mm[k].tolist()])
        else:
            j = k
            while j + 1 < len(tp) and tp.line[j + 1] == line and tp.is_arc[j + 1]:
                j += 1
            a, b, n = PLANE_AXES[tp.plane[j]]
            e, c = tp.end_mm[j], tp.center_mm[j]
            turns = (j - k + 1) * (1 if kind == MotionKind.ARC_CCW else -1)
            out.append(["arc", line, [e[a], e[b], c[a], c[b], e[n], turns]])
            k = j
        k += 1
    return out


def _mismatch(text: str, ref: dict) -> str | None:
    try:
        got = _moves(text)
    except GCodeError as err:
        if "needs LinuxCNC's interpreter" in err.reason:
            return None  # left to LinuxCNC on purpose
        if ref["error"] is None:
            return f"nctwin refused what LinuxCNC runs: {err}"
        # (LinuxCNC reports an error found while reading a line with the next line's number)
        if err.line not in (ref["error"][0], ref["error"][0] - 1):
            return f"LinuxCNC's error {ref['error']}, nctwin's {err}"
        return None
    if ref["error"] is not None:
        return f"LinuxCNC refused ({ref['error']}), nctwin read it"
    if len(got) != len(ref["moves"]):
        return f"{len(ref['moves'])} LinuxCNC moves, {len(got)} nctwin blocks"
    for want, have in zip(ref["moves"], got, strict=True):
        if want[:2] != have[:2] or not np.allclose(want[2], have[2], rtol=1e-12, atol=1e-9):
            return f"LinuxCNC {want}, nctwin {have}"
    return None


#: Programs written to exercise each construct; each runs in LinuxCNC.
PROGRAMS = [
    "G0 X0 Y0 Z10\nF60\nG98 G81 X10 Y5 R2 Z-3\nX20\nG80\nG0 X0",
    "G0 X0 Y0 Z1\nF60\nG98 G81 X5 R2 Z-1\nG99 X6\nG98 X7",
    "G0 X1 Y0 Z5\nF60\nG91 G81 X10 Y0 R-3 Z-4 L3\nG90 G83 X0 Y0 R1 Z-3 Q1.5",
    "G0 Z5\nF60\nG73 X1 R1 Z-3 Q0.7 L2\nG98 G73 X2 Y2 R2 Z-4 Q1.1",
    "M3 S100\nG0 Z5\nF60\nG82 X1 R2 Z-1 P0.5\nG85 X2 R2 Z-1\nG86 X3 R2 Z-1 P0.2",
    "M3 S100\nG0 Z5\nF60\nG89 X1 R2 Z-1 P0.5\nG84 X2 R2 Z-1\nG88 X3 R2 Z-1 P0.1\nG0 X0",
    "M4 S100\nG0 Z5\nF60\nG74 X1 R2 Z-1 P0.3",
    "M3\nG0 X0 Y0 Z2\nF60\nG87 X5 Y5 R-5 Z-8 I1 J0 K-6\nG91 G87 X1 R1 Z-1 I0 J1 K0.5",
    "G18 G0 X0 Y10 Z0\nF60\nG81 X5 Z5 R2 Y-3\nG19 G98 G83 Y1 Z1 R2 X-3 Q1",
    "G20 G0 X0 Y0 Z1\nF10\nG98 G83 X1 R0.1 Z-0.3 Q0.25\nG21 G80 G0 X0",
    "G0 X0\nG92 X10\nG0 X0\nG92.2\nG0 X1\nG92.3\nG0 X2\nG92.1\nG0 X3\nG92.3\nG0 X4",
    "G0 X5 Y5\nG92 X0 Y0\nG53 G0 X1\nG0 X5 Y0\nG90.1 G3 X-5 Y0 I0 J0 F60\nG91 G0 X1\nG92 X0",
    "G0 X2 Y1 Z3\nG92 Z0\nF60\nG98 G81 X1 R1 Z-1\nG92.1\nX3",
    "G0 X0 Y0\nG4 P.001 G0 X1 Y1\nG4 P0.2 G1 X2 F60\nF30 G4 P0.1",
    "G0 X10 Y0\nG2 I-10 F600\nG3 I-5 P3\nG3 X-10 Y0 Z-6 I-10 J0 P2\nJ5",
    "G21\nG20 F6 G1 X1\nG21 F6 X2\nG20 G4 P1 G0 X1",
]


def test_programs_run_as_in_linuxcnc(linuxcnc_interpreter):
    refs = linuxcnc_interpreter(PROGRAMS)
    errors = {text: ref["error"] for text, ref in zip(PROGRAMS, refs, strict=True) if ref["error"]}
    assert errors == {}
    problems = {text: _mismatch(text, ref) for text, ref in zip(PROGRAMS, refs, strict=True)}
    assert {t: p for t, p in problems.items() if p} == {}


def _random_program(rng: np.random.Generator) -> str:
    """A program of random cycles, offsets, dwells, full circles and unit changes."""
    plane = str(rng.choice(["G17", "G17", "G18", "G19"]))
    depth, ij = {"G17": ("Z", "IJ"), "G18": ("Y", "KI"), "G19": ("X", "JK")}[plane]
    lines = [plane, "G20" if rng.random() < 0.3 else "G21", f"F{rng.integers(10, 2000)}", "M3"]
    lines.append(
        f"G0 X{rng.uniform(-20, 20):.3f} Y{rng.uniform(-20, 20):.3f} Z{rng.uniform(0, 20):.3f}"
    )

    def num(span=30.0):
        return f"{rng.uniform(-span, span):.3f}"

    cycle = False
    for _ in range(rng.integers(1, 10)):
        op = rng.integers(0, 10)
        if op <= 3:
            code = str(rng.choice(["G81", "G82", "G83", "G73", "G85", "G86", "G87", "G88", "G89"]))
            incremental = rng.random() < 0.25
            words = ["G91" if incremental else "G90", str(rng.choice(["G98", "G99", ""])), code]
            words += [
                f"{a}{num(5 if incremental else 20)}"
                for a in "XYZ"
                if a != depth and rng.random() < 0.7
            ]
            r = rng.uniform(-3, 3) if incremental else rng.uniform(-5, 10)
            bottom = -rng.uniform(0, 8) if incremental else r - rng.uniform(0, 15)
            words += [f"R{r:.3f}", f"{depth}{bottom:.3f}"]
            words += [f"P{rng.uniform(0, 1):.2f}"] if code in ("G82", "G86", "G88", "G89") else []
            words += [f"Q{rng.uniform(0.3, 3):.3f}"] if code in ("G83", "G73") else []
            words += [f"I{num(2)} J{num(2)} K{num(5)}"] if code == "G87" else []
            words += [f"L{rng.integers(1, 4)}"] if rng.random() < 0.2 else []
            lines.append(" ".join(w for w in words if w))
            cycle = True
        elif op == 4 and cycle:
            lines.append(f"X{num()} Y{num()}")
        elif op == 5:
            lines.append(
                str(rng.choice(["G80", "G90", "G91", "G98", "G99", "G20", "G21", "M5", "M3"]))
            )
        elif op == 6:
            lines.append(f"G92 X{num()} Y{num()}" if rng.random() < 0.6 else f"G92 Z{num()}")
        elif op == 7:
            lines.append(str(rng.choice(["G92.1", "G92.2", "G92.3"])))
        elif op == 8:
            lines.append(f"G4 P{rng.uniform(0, 1):.3f} G90 G1 X{num()} Y{num()}")
            cycle = False
        else:
            turns = f" P{rng.integers(1, 4)}" if rng.random() < 0.5 else ""
            lines.append(f"G90 G{rng.choice([2, 3])} {ij[0]}{num(5)} {ij[1]}{num(5)}{turns}")
            cycle = False
    return "\n".join(lines)


def test_random_programs_run_as_in_linuxcnc(linuxcnc_interpreter):
    rng = np.random.default_rng(2026)
    texts = [_random_program(rng) for _ in range(150)]
    refs = linuxcnc_interpreter(texts)
    assert sum(ref["error"] is None for ref in refs) > 100  # most run in LinuxCNC
    problems = {text: _mismatch(text, ref) for text, ref in zip(texts, refs, strict=True)}
    assert {t: p for t, p in problems.items() if p} == {}
