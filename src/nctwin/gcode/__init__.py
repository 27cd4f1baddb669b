"""G-code (RS274/NGC subset of a 3-axis mill) to :class:`~nctwin.toolpath.Toolpath` and back.

The reader is vectorised: the text is lexed into words with numpy on the raw bytes, modal state is
carried forward with cumulative maxima, and positions with anchored cumulative sums. Nothing loops
over lines in Python, which is what makes it fast (see ``benchmarks/parse.py``). Only the rare
constructs that carry state from line to line in ways a cumulative sum cannot (G92 offsets and
canned cycles) are interpreted line by line, and only on the lines that hold them.

What is read
------------
The words of a line run in LinuxCNC's order of execution, not in the order they are written:
F, S, T and the spindle M-codes first, then the dwell G4, the plane, units, path control and
distance modes, G98/G99, the G92 offsets, the motion, and last the stops M0, M1, M2, M30 and M60
(their events follow the line's blocks). So ``G4 P1 G0 X1`` dwells, then moves; ``G20 F6`` in a
program in G21 sets 6 mm/min and keeps it when the units change (LinuxCNC rescales the feed rate
in ``convert_length_units``).

* Motion G0, G1, G2, G3: I/J/K centres, R radii of both signs, helices, full circles (also with
  no end-point words, ``G2 I5``), P turns (an arc of P turns is read as P-1 full turns then the
  arc). Dwell G4 (P in seconds by default, ``dwell_p_unit="ms"`` for Fanuc-style milliseconds;
  a G4 with X and no P is a Fanuc dwell of X seconds), alone or before the motion of its line.
* Canned cycles G73, G74, G81-G89 with G98/G99 and R, Q, P, L words, in the G17, G18 and G19
  planes, expanded into the rapids, feeds and dwells LinuxCNC 2.9 makes of them
  (``interp_cycles.cc``): every block keeps the line of the cycle, runs in exact-path mode as in
  LinuxCNC (but a first rapid up to R from below it, which LinuxCNC makes before switching), and
  G73/G83 retract by LinuxCNC 2.9's ``G83_RAPID_DELTA`` (0.010 in). G74 and G84 are read in the
  G17 plane only (in the others LinuxCNC 2.9 feeds along swapped axes). Before any G98/G99 the
  tool retracts to R (LinuxCNC's retract mode starts as its zero value, G99). Spindle stops,
  reversals and orientations inside G74, G84, G86, G87 and G88 have no motion effect and make no
  events; G88 leaves the tool at the hole bottom for the operator and the next move starts
  there, while the coordinates continue from the clearance height as in LinuxCNC.
* Offsets G92, G92.1 (clears them and zeros parameters 5211-5213), G92.2 (clears them, keeps the
  parameters), G92.3 (restores them from the parameters, which start at zero). Positions are
  machine positions: program coordinates plus the G92 offset.
* Reference-point returns G28 and G30, as LinuxCNC runs them (``convert_home``) and as a Fanuc
  control runs the ``G91 G28 Z0.`` of a CAM post before a tool change: a rapid to the
  intermediate point of the line's axis words, read in the distance mode in force (in G91,
  ``Z0`` is where Z is), then a rapid of the named axes to the reference point; without axis
  words, every axis goes to it (after a zero-length rapid, as in LinuxCNC). Both blocks carry
  the line's number; the motion mode in force is kept (a later line without a G-word moves in
  it), and an explicit motion code on the line other than G80 is refused. The reference points
  are LinuxCNC's parameters #5161-#5163 (G28) and #5181-#5183 (G30), here
  ``g28_reference_mm`` and ``g30_reference_mm``: X, Y, Z in mm, in the Toolpath's (machine)
  coordinates, which a G92 offset does not move; LinuxCNC's zeros by default. A real machine's
  home is its own: there, give the home position minus the work offset (and, along Z, minus
  the tool length). G28.1 and G30.1, which set the points, need LinuxCNC's interpreter.
* Modal state: G17/G18/G19, G20/G21 (converted to mm), G90/G91, G90.1/G91.1, G94 (which runs
  before the F of its line and clears the feed, as LinuxCNC's does), G98/G99, F.
  A G80 beside another motion code of its line gives way to it, as in LinuxCNC (``read_g``).
* Prologue codes kept as state with no motion: G40, G43 H and G49 (the tool's offsets from
  ``tool_table=``, zero without one; they shift the program's coordinates as LinuxCNC's do,
  so the tool moves by them at the next absolute move of the axis; a canned cycle under a
  non-zero offset and G43 without H need LinuxCNC's interpreter), G53 (machine coordinates,
  ignoring G92; work offsets are taken as zero), G54-G59.3, G80, G61, G61.1 and G64 with P
  (blending tolerance) and Q (naive CAM tolerance).
* N numbers, ``( )`` and ``;`` comments, block delete ``/`` (off by default: the block runs, as
  with the switch off), ``%`` tape markers, Fanuc program numbers (a line that is only ``O1234``
  and a comment), M, S and T words (kept as events), any case, with or without spaces. M2 and M30
  end the program: what follows is not read, as on a control.

Anything else LinuxCNC reads (O-word subroutines and loops, ``#`` parameters, expressions, cutter
compensation, ...) raises :class:`GCodeError` with ``<construct> needs LinuxCNC's interpreter:
run make linuxcnc``; rotary axes and codes LinuxCNC lacks are refused too. Every error of a file
is reported, up to 20, one ``file:line: reason`` line each.

Dialects
--------
``dialect="rs274ngc"`` (default) reads the program as above, LinuxCNC's language.
``dialect="fanuc"`` (native reader only) reads a Fanuc milling control's, as a Fanuc-style CAM
post (a Hurco in ISO mode, a Fanuc 0i) writes it:

* P in G4 and in canned cycles is in milliseconds (an explicit ``dwell_p_unit`` wins).
* ``M29 S..`` before a G84 or G74 selects rigid tapping for that cycle, until G80 or another
  motion code. Rigid tapping moves as floating tapping does (feed in, dwell P, feed out to R or
  the initial level); the spindle, which the control then turns itself, need not be turning
  before. A canned cycle other than G84/G74 after an M29 is refused, naming the M29's line.
* G76 is fine boring, not LinuxCNC's threading: per hole, rapids over it and to R, a feed to
  the bottom, the dwell P, a rapid shift by Q (its sign ignored) along the plane's first axis
  in its + direction (+X in G17), a rapid out to R (G99) or the initial level (G98), and a
  rapid shift back (:mod:`nctwin.gcode._cycles` gives the sources). G98/G99 and L repeats as
  in the other cycles.
* Refused, one ``file:line: reason`` each, as codes this reader does not read as a Fanuc
  control does: G87 (Fanuc's back boring shifts by Q), G92.1-G92.3, G90.1, G91.1, G5, G5.1,
  G8, G52, G10, M98/M99 subprograms, K repeats of a canned cycle (write L); and whatever the
  rs274ngc dialect leaves to LinuxCNC's interpreter, which reads RS274/NGC only.

The reader makes geometry and dwells: the spindle's orientation, stops, restarts and reversals
(M19 in G76, the reversal at the bottom of a tap) take no time here. G73 and G83 retract by
LinuxCNC's 0.010 in, where a Fanuc control retracts by its parameters (No. 5114 and 5115 on a
0i).

Two readers
-----------
:func:`parse` and :func:`parse_file` take ``reader="auto"`` (default), ``"native"`` or
``"linuxcnc"``. ``"native"`` is the reader above. ``"linuxcnc"`` runs the program through
LinuxCNC's own rs274ngc interpreter (``make linuxcnc`` installs it; see
:mod:`nctwin.gcode._interp`), which reads the whole language and gives the moves LinuxCNC runs,
as the same :class:`~nctwin.toolpath.Toolpath` (its G5/G5.1 splines as the biarcs LinuxCNC's
task runs, :mod:`nctwin.gcode._splines`, not the preview's lines; of the M, S and T words it
keeps the M-words LinuxCNC's task waits for, as far as the interpreter's modal state shows them,
:mod:`nctwin.gcode._task_words`); it takes a LinuxCNC tool table
(``tool_table=``: a machine profile's :class:`~nctwin.machine.ToolTable`, such as
``linuxcnc_sim``'s, LinuxCNC's own sim table, or a ``.tbl`` file; default
:data:`LINUXCNC_TOOL_TABLE`, the table of nctwin's own LinuxCNC configuration); a tool the
table lacks runs with size 0 unless the program's cutter compensation or length offset needs
its size (:func:`complete_tool_table`). The native reader takes the tool length offsets of
``G43 H<n>`` from the same table (:mod:`nctwin.gcode._tools`). ``"auto"`` is the
native reader, and where that refuses only constructs that need the interpreter, the
interpreter if :func:`interpreter_available`; otherwise the native error stands. The two agree
to 1e-6 mm on every program both read (``tests/test_gcode_interp.py``).

To learn which reader read a program, call :func:`read` or :func:`read_file`: they return a
:class:`ReadResult` with ``toolpath`` and ``reader`` (``"native"`` or ``"linuxcnc"``)::

    result = read_file("part.ngc")            # reader="auto"
    result.toolpath, result.reader            # (Toolpath, "linuxcnc") for a program with O-words
"""

from ._cycles import G83_RAPID_DELTA_IN as G83_RAPID_DELTA_IN
from ._dump import dump
from ._errors import MAX_ERRORS as MAX_ERRORS
from ._errors import GCodeError
from ._fanuc import DIALECTS as DIALECTS
from ._interp import MAX_MOVES as MAX_MOVES
from ._interp import TIMEOUT_BASE_S as TIMEOUT_BASE_S
from ._interp import TIMEOUT_S_PER_MB as TIMEOUT_S_PER_MB
from ._interp import interpreter_available
from ._modal import MAX_BLOCKS_PER_LINE as MAX_BLOCKS_PER_LINE
from ._modal import MM_PER_INCH as MM_PER_INCH
from ._reader import read_text
from ._select import READERS as READERS
from ._select import ReadResult, parse, parse_file, read, read_file
from ._tools import LINUXCNC_TOOL_TABLE as LINUXCNC_TOOL_TABLE
from ._tools import complete_tool_table

__all__ = [
    "GCodeError",
    "ReadResult",
    "complete_tool_table",
    "dump",
    "interpreter_available",
    "parse",
    "parse_file",
    "read",
    "read_file",
    "read_text",
]
