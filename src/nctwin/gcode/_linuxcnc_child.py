"""The child process of :mod:`nctwin.gcode._interp`: runs one program through LinuxCNC's
rs274ngc interpreter (its preview module ``gcode``) and writes what the canon reported.

This file is not imported by nctwin: ``/usr/bin/python3`` (the Python LinuxCNC's module is built
for) runs it as a script, with one argument, a JSON object:

``program``
    The program file (already instrumented by the parent: every line ends in ``()``).
``tool_table``
    A LinuxCNC tool table (``.tbl``), loaded as LinuxCNC's ``iocontrol`` loads it.
``unitcode``, ``initcode``
    What the interpreter runs before the program (``G21``/``G20``; the path-mode sentinel).
``block_delete``
    The block-delete switch.
``parameters``
    ``[number, value]`` pairs, the interpreter's parameter file (the G28 and G30 reference
    points, #5161-#5163 and #5181-#5183, in mm, the machine's units); the others are zero.
``max_moves``, ``deadline_s``
    Limits: canonical moves, and seconds of wall-clock time (checked when LinuxCNC asks).
``home``, ``out``
    A private folder (LinuxCNC's tool data are shared through ``$HOME/.tool.mmap``) and the file
    the results go to.

The output file holds a JSON header line, then the tables as raw bytes, in this order:

* moves, float64, 7 columns: kind (0 rapid, 1 feed, 2 arc, 4 dwell), then for lines ``x y z``,
  for arcs ``first_end second_end axis_end first_centre second_centre rotation``, for dwells the
  time in the first column; zeros elsewhere. Lengths in inches, as the module reports them.
* events (one per ``next_line``): the moves made before it (float64), then the reported state
  itself, the ``settings`` (5 float64) and ``gcodes``/``mcodes`` (int32) arrays of the
  ``gcode.linecode`` object, copied from its memory (the header gives their lengths).
* modal records, float64, 15 columns: the moves made before it, feed (in/min, NaN before the
  first F), canon plane (1 XY, 2 YZ, 3 XZ), G92 offset (3), G5x offset (3), tool length offset
  (3), XY rotation (degrees), then the call that made it (:data:`CAUSES`; -1 the initial state)
  and the events (lines) reported before it.

The callbacks are closures over local tables, not methods: they run once per move, and a
closure's names cost less than attribute look-ups.
"""

import array
import ctypes
import json
import math
import os
import struct
import sys
import time

#: Offset of ``settings[]`` in a ``gcode.linecode`` object: after ob_refcnt and ob_type.
_SETTINGS_OFFSET = 2 * ctypes.sizeof(ctypes.c_void_p)
#: The canon calls of a modal record, by its cause column: feed, plane, and the offsets
#: LinuxCNC's task runs only once the motion has stopped (G92, G5x, tool length, XY rotation).
CAUSES = ("feed", "plane", "g92", "g5x", "tool", "rotation")


class _Tool(ctypes.Structure):
    """LinuxCNC's ``CANON_TOOL_TABLE`` (emctool.h)."""

    _fields_ = [
        ("toolno", ctypes.c_int),
        ("pocketno", ctypes.c_int),
        ("offset", ctypes.c_double * 9),
        ("diameter", ctypes.c_double),
        ("frontangle", ctypes.c_double),
        ("backangle", ctypes.c_double),
        ("orientation", ctypes.c_int),
    ]


class _Stop(Exception):
    """Raised inside a canon call to stop the interpreter; the reason is kept on the canon."""


class _Tools:
    """LinuxCNC's tool data (libtooldata): a fresh memory map loaded from the tool table, as
    ``iocontrol`` makes it; the interpreter finds tools in it by number."""

    def __init__(self, path):
        lib = ctypes.CDLL("libtooldata.so.0")
        creator = lib._Z17tool_mmap_creatorPK13EMC_TOOL_STATi
        creator.argtypes = [ctypes.c_void_p, ctypes.c_int]
        load = lib._Z13tooldata_loadPKcPPc
        load.argtypes = [ctypes.c_char_p, ctypes.c_void_p]
        self._get = lib._Z12tooldata_getP16CANON_TOOL_TABLEi
        self._get.argtypes = [ctypes.POINTER(_Tool), ctypes.c_int]
        creator(None, 0)  # a non-random tool changer, as nctwin's LinuxCNC configuration
        if load(path.encode(), None) != 0:
            raise OSError(f"cannot read the tool table {path}")

    def get(self, index):
        t = _Tool()
        if self._get(ctypes.byref(t), index) != 0:
            return (-1,) + (0.0,) * 12 + (0,)
        return (t.toolno, *t.offset, t.diameter, t.frontangle, t.backangle, t.orientation)


class Canon:
    """The callbacks of LinuxCNC's preview module: every move, dwell, state change and line is
    appended to flat tables."""

    def __init__(self, job, tools):
        self.parameter_file = os.path.join(job["home"], "rs274ngc.var")
        self.tools, self.block_delete = tools, bool(job["block_delete"])
        self.deadline = time.monotonic() + float(job["deadline_s"])
        self.moves, self.modal = array.array("d"), array.array("d")
        self.event_at, self.states = array.array("d"), bytearray()
        self.stop = self.spindle = None
        self.n_codes = None
        self.state = [math.nan, 1.0] + [0.0] * 10
        self._bind(int(job["max_moves"]) * 7)
        self._push(-1)

    def _bind(self, max_rows):
        """The per-move callbacks, as closures."""
        moves, add = self.moves, self.moves.extend

        def full():
            if len(moves) >= max_rows:
                self.stop = ["moves"]
                raise _Stop()

        def straight_traverse(x, y, z, *rest):
            add((0.0, x, y, z, 0.0, 0.0, 0.0))
            if len(moves) >= max_rows:
                full()

        def straight_feed(x, y, z, *rest):
            add((1.0, x, y, z, 0.0, 0.0, 0.0))
            if len(moves) >= max_rows:
                full()

        def arc_feed(e1, e2, c1, c2, rotation, e3, *rest):
            add((2.0, e1, e2, e3, c1, c2, float(rotation)))
            if len(moves) >= max_rows:
                full()

        def dwell(seconds):
            add((4.0, seconds, 0.0, 0.0, 0.0, 0.0, 0.0))

        at, states, string_at, n_moves = self.event_at.append, self.states, ctypes.string_at, len

        def next_line(st):
            at(n_moves(moves))
            states.extend(string_at(id(st) + _SETTINGS_OFFSET, size))

        def first_next_line(st):
            nonlocal size
            self.n_codes = [len(st.gcodes), len(st.mcodes)]
            size = 40 + 4 * sum(self.n_codes)
            raw = ctypes.string_at(id(st) + _SETTINGS_OFFSET, size)
            settings = struct.unpack_from("5d", raw)
            gcodes = struct.unpack_from(f"{self.n_codes[0]}i", raw, 40)
            named = (st.feed_rate, st.sequence_number, st.motion_mode, st.units, st.path_mode)
            if named != (settings[1], gcodes[0], gcodes[1], gcodes[5], gcodes[11]):
                self.stop = ["internal", "unknown layout of gcode.linecode"]
                raise _Stop()  # never guess at memory
            self.next_line = next_line
            next_line(st)

        size = 0
        self.straight_traverse, self.straight_feed = straight_traverse, straight_feed
        self.arc_feed, self.dwell, self.next_line = arc_feed, dwell, first_next_line

    # ---- state
    def _push(self, cause):
        self.modal.append(len(self.moves))
        self.modal.extend(self.state)
        self.modal.extend((cause, len(self.event_at)))

    def set_feed_rate(self, rate):
        self.state[0] = rate
        self._push(0)

    def set_plane(self, plane):
        self.state[1] = plane
        self._push(1)

    def set_g92_offset(self, x, y, z, *rest):
        self.state[2:5] = [x, y, z]
        self._push(2)

    def set_g5x_offset(self, index, x, y, z, *rest):
        self.state[5:8] = [x, y, z]
        self._push(3)

    def tool_offset(self, x, y, z, *rest):
        self.state[8:11] = [x, y, z]
        self._push(4)

    def set_xy_rotation(self, degrees):
        self.state[11] = degrees
        self._push(5)

    def comment(self, text):  # every line has one (the parent's mark): nothing to keep
        return None

    def rigid_tap(self, *args):
        self.stop = ["refused", "rigid tapping (G33.1) is spindle-synchronised motion"]
        raise _Stop()

    def straight_probe(self, *args):
        self.stop = ["refused", "probing (G38.n) has no tool path without a probe"]
        raise _Stop()

    # ---- questions the interpreter asks
    def get_external_length_units(self):
        return 1.0  # machine units: mm, as nctwin's LinuxCNC configuration (LINEAR_UNITS = mm)

    def get_external_angular_units(self):
        return 1.0

    def get_axis_mask(self):
        return 7  # X, Y, Z

    def get_block_delete(self):
        return self.block_delete

    def change_tool(self, index):
        self.spindle = index

    def get_tool(self, index):
        # M6 (CHANGE_TOOL) on a non-random tool changer: iocontrol copies the tool at ``index``
        # into index 0, the spindle, where the interpreter reads it when it reloads the table
        return self.tools.get(self.spindle if index == 0 and self.spindle else index)

    def check_abort(self):
        if time.monotonic() > self.deadline:
            self.stop = ["time"]
            return True
        return False

    def __getattr__(self, name):  # messages, tool changes, ...: nothing to keep
        if name.startswith("__"):
            raise AttributeError(name)
        return _ignore


def _ignore(*args):
    return None


def main():
    job = json.loads(sys.argv[1])
    os.environ["HOME"] = job["home"]  # where libtooldata puts .tool.mmap
    header = {"error": None, "stop": None}
    canon = None
    try:
        import gcode

        canon = Canon(job, _Tools(job["tool_table"]))
        with open(canon.parameter_file, "w") as f:  # in increasing order, as LinuxCNC reads it
            f.writelines(f"{int(k)} {float(v)!r}\n" for k, v in sorted(job["parameters"]))
        result, line = gcode.parse(job["program"], canon, job["unitcode"], job["initcode"])
        if result > gcode.MIN_ERROR:
            header["error"] = [line, gcode.strerror(result)]
    except BaseException as exc:  # a stop raised in a callback arrives as LinuxCNC's error
        if canon is None or canon.stop is None:
            header["stop"] = ["internal", f"{type(exc).__name__}: {exc}"]
    if canon is None:
        tables = ()
    else:
        header["stop"] = canon.stop or header["stop"]
        header["codes"] = canon.n_codes
        tables = (canon.moves, canon.event_at, canon.states, canon.modal)
    header["bytes"] = [len(memoryview(t).cast("B")) for t in tables]
    with open(job["out"], "wb") as f:
        f.write(json.dumps(header).encode() + b"\n")
        for t in tables:
            f.write(t)


if __name__ == "__main__":
    main()
