r"""Part programs in the whole RS274/NGC language, as a shop's CAM system or a programmer at the
machine writes them: canned drilling cycles, cutter compensation, subroutines, parameters and
expressions, offsets and units, arcs and helices outside the XY plane, splines and NURBS, and
the tool changes, pauses and dwells a control's task waits for.

Paper 1's training programs and the CAM-style programs (:mod:`nctwin.programs.training`,
:mod:`nctwin.programs.camstyle`) are chains of G1 lines that the native reader reads. A shop's
real programs are mostly not: a drilling job is a list of ``G81``/``G83`` cycles, a contour is
programmed on the part's outline with ``G41``/``G42`` and the control offsets it by the tool's
radius, a family of parts is one subroutine called with parameters. These programs exercise
exactly those constructs, so that LinuxCNC's recordings of them check that a method times the
moves LinuxCNC makes of them: the plunges and retracts of a cycle, the offset path with its
entry move and the arcs that compensation inserts at outside corners, a subroutine's path
repeated.

Every program is fixed text (no random draw): :data:`LANGUAGE_PROGRAMS` maps a name to a
function that returns it. All run on ``linuxcnc_sim`` (mm, X/Y 200 mm/s, Z 100 mm/s) in under
a minute each. Cutter compensation is programmed with the tool diameter in the program
(``G41.1``/``G42.1 D``), so the path does not depend on a tool table.
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["LANGUAGE_PROGRAMS"]


def drill_cycles() -> str:
    """A 4 x 5 hole grid drilled with G81, spot-faced with G82 (dwell), peck-drilled with G83
    and G73, bored with G85 and G89, in G98 and G99 retract modes, with L repeats in G91 and a
    row in the ZX plane (G18)."""
    return """\
(nctwin language program: canned drilling cycles)
G21 G17 G90 G94 G40 G49 G80
G64 P0.02
F600
G0 Z10
G0 X0 Y0
(row 1: centre drill G81, return to R between holes)
G99 G81 X10 Y10 Z-2 R1 F300
X25
X40
X55
X70
G80
(row 2: spot face G82 with a dwell, return to the initial Z)
G98 G82 X10 Y25 Z-3 R1 P0.2 F250
X25
X40
X55
X70
G80
(row 3: peck drilling G83, Q 2 mm)
G0 Z12
G99 G83 X10 Y40 Z-12 R2 Q2 F400
X25
X40
G73 X55 Y40 Z-10 R2 Q1.5 F450
X70
G80
(row 4: G91 with L repeats, incremental spacing 15 mm)
G90 G0 X-5 Y55
G91 G99 G81 X15 Y0 Z-4 R-9 L5 F350
G90 G80
(boring: G85 feeds out, G89 dwells at the bottom)
G98 G85 X10 Y70 Z-6 R1 F200
X40
G89 X70 Y70 Z-6 R1 P0.3 F200
G80
(a row in the ZX plane, drilling along Y)
G18 G0 Y5
G99 G81 X10 Z-20 Y-3 R3 F300
X30
X50
G80 G17
G0 Z20
G0 X0 Y0
M2
"""


def cutter_compensation() -> str:
    """An outside contour with rounded and sharp corners cut with G42.1 (right of the path,
    climb milling outside), and an inside pocket wall with G41.1, each with a straight entry
    move, an arc lead-in and G40 on the exit; tool diameter 6 mm then 10 mm."""
    return """\
(nctwin language program: cutter compensation)
G21 G17 G90 G94 G40 G49 G80
G64 P0.02
G0 Z5
G0 X-20 Y-20
G1 Z-2 F300
(outside contour, right compensation, D 6 mm)
G42.1 D6 F900
G1 X0 Y-10
G1 X0 Y0
G1 X60 Y0
G3 X70 Y10 R10
G1 X70 Y40
G3 X60 Y50 I-10 J0
G1 X30 Y50
G1 X20 Y35
G1 X0 Y50
G1 X0 Y0
G1 X10 Y-10
G40 G1 X-20 Y-20
G0 Z5
(inside wall of a 30 x 20 mm pocket, corners r 8, left compensation, D 10 mm)
G0 X35 Y25
G1 Z-3 F300
G41.1 D10 F700
G1 X35 Y15
G1 X42
G3 X50 Y23 I0 J8
G1 Y27
G3 X42 Y35 I-8 J0
G1 X28
G3 X20 Y27 I0 J-8
G1 Y23
G3 X28 Y15 I8 J0
G1 X35
G40 G1 X35 Y25
G0 Z5
(a circle of three turns around the part, compensation on)
G0 X95 Y25
G1 Z-1 F300
G42.1 D6 F1200
G1 X85 Y25
G2 X85 Y25 I-50 J0 P3
G40 G1 X95 Y25
G0 Z20
G0 X0 Y0
M2
"""


def subroutines() -> str:
    """One subroutine cuts a circular pocket at a centre, radius and depth given as parameters,
    in step-downs (a while loop) and in rings (a nested while loop); it is called for six
    pockets from a repeat loop, and a second subroutine with an if/else picks the depth."""
    return """\
(nctwin language program: subroutines, loops, parameters)
G21 G17 G90 G94 G40 G49 G80
G64 P0.02
#<_safe> = 5
#<_stepdown> = 1.5
#<_stepover> = 2.5
o100 sub
  (#1 x centre, #2 y centre, #3 radius, #4 depth, #5 feed)
  G0 Z#<_safe>
  G0 X#1 Y#2
  G1 Z0 F[#5 / 3]
  #<z> = 0
  o110 while [#<z> GT -#4]
    #<z> = [#<z> - #<_stepdown>]
    o111 if [#<z> LT -#4]
      #<z> = -#4
    o111 endif
    G1 Z#<z> F[#5 / 3]
    #<r> = #<_stepover>
    o120 while [#<r> LT #3]
      G1 X[#1 + #<r>] Y#2 F#5
      G3 X[#1 + #<r>] Y#2 I[-#<r>] J0
      #<r> = [#<r> + #<_stepover>]
    o120 endwhile
    G1 X[#1 + #3] Y#2
    G3 X[#1 + #3] Y#2 I[-#3] J0
    G1 X#1 Y#2
  o110 endwhile
  G0 Z#<_safe>
o100 endsub
o200 sub
  (#1 index: even pockets shallow, odd deep)
  o210 if [[#1 MOD 2] EQ 0]
    #<depth> = 3
  o210 else
    #<depth> = 4.5
  o210 endif
  o100 call [20 + 35 * [#1 MOD 3]] [20 + 35 * FIX[#1 / 3]] [8 + #1] [#<depth>] [900]
o200 endsub
G0 Z#<_safe>
#<i> = 0
o300 repeat [6]
  o200 call [#<i>]
  #<i> = [#<i> + 1]
o300 endrepeat
G0 Z20
G0 X0 Y0
M2
"""


def parametric_curve() -> str:
    """An engraved rose curve r = 30 cos(4 t) (eight petals) in 1440 chords and an Archimedean
    spiral in chords of about 1 mm, each computed in a while loop with named parameters, sin,
    cos and an arc-length step."""
    return """\
(nctwin language program: parametric engraving)
G21 G17 G90 G94 G40 G49 G80
G64 P0.01
#<cx> = 60
#<cy> = 50
G0 Z5
G0 X[#<cx> + 30] Y#<cy>
G1 Z-0.3 F200
F1200
(rose: 1440 chords, one every 0.25 degree of t)
#<n> = 1440
#<k> = 1
o100 while [#<k> LE #<n>]
  #<t> = [360 * #<k> / #<n>]
  #<r> = [30 * COS[4 * #<t>]]
  G1 X[#<cx> + #<r> * COS[#<t>]] Y[#<cy> + #<r> * SIN[#<t>]]
  #<k> = [#<k> + 1]
o100 endwhile
G0 Z5
(Archimedean spiral r = 2 + 1.5 t / 360, five turns, 1 mm chords)
G0 X[#<cx> + 2] Y#<cy>
G1 Z-0.3 F200
F1500
#<t> = 0
o200 while [#<t> LT 1800]
  #<r> = [2 + 1.5 * #<t> / 360]
  #<t> = [#<t> + 180 / [3.14159265358979 * #<r>]]
  G1 X[#<cx> + #<r> * COS[#<t>]] Y[#<cy> + #<r> * SIN[#<t>]]
o200 endwhile
G0 Z20
G0 X0 Y0
M2
"""


def offsets_units() -> str:
    """A slot pattern (a subroutine) cut twice, at a G92 offset and at another after G92.1,
    then a slot in inches at a G92 offset again, with G43 H and G49 around it and a G53 move to
    a machine position. The units line ``G20 F40`` sets F before the units change, as LinuxCNC
    executes a line: the plunge after it runs at 40 mm/min, not 40 in/min."""
    return """\
(nctwin language program: offsets and units)
G21 G17 G90 G94 G40 G49 G80
G64 P0.05
o100 sub
  G0 Z2
  G0 X0 Y0
  G1 Z-1 F300
  G1 X40 F1000
  G3 X40 Y10 R5
  G1 X0
  G2 X0 Y20 R5
  G1 X40
  G0 Z2
o100 endsub
G43 H0
G0 X0 Y0 Z5
G92 X-10 Y-10
o100 call
G92.1
G0 X60 Y0
G92 X0 Y0
o100 call
G92.1
G20 F40
G0 X0 Y1.5 Z0.2
G92 X0 Y0
G1 Z-0.04
F30
G1 X1.6
G3 X1.6 Y0.4 R0.2
G1 X0
G0 Z0.2
G92.1
G21
G49
G53 G0 Z20
G0 X0 Y0
M2
"""


def plane_arcs() -> str:
    """Arcs and helices in the ZX (G18) and YZ (G19) planes, where Z's lower limits (100 mm/s,
    500 mm/s^2 on ``linuxcnc_sim``) bound the arc: half, quarter and full circles of 2-40 mm
    radius at 10-100 mm/s, joined to lines at right angles, tangentially, by a reversal and to
    each other; a helical half turn in each plane and a full helical turn; a dwell after an
    arc, and an arc as the last move."""
    return """\
(nctwin language program: arcs and helices in the ZX and YZ planes)
G21 G17 G90 G94 G40 G49 G80
G64 P0.02
G0 X0 Y0 Z0
(G18: half circles of 10 mm at two feeds between lines, at right angles)
G18 G1 X10 F1200
G2 X30 Z0 I10 K0
G1 X40
G3 X60 Z0 I10 K0 F6000
(a tangent S of two half circles of 5 mm)
G2 X70 Z0 I5 K0 F3000
G1 X80
(quarter circles of 25 and 40 mm, a tangent line between and after)
G3 X105 Z25 I25 K0
G1 X115
G2 X155 Z65 I0 K40 F1800
G1 Z80
(a helical half turn of 10 mm down 10 mm in Y, then full circles of 5 and 2 mm)
G2 X175 Z80 Y-10 I10 K0 F1200
G1 X185 F2000
G2 X185 Z80 I5 K0 F3000
G3 X185 Z80 I2 K0 F600
G0 X200 Y0 Z0
(G19: the same in the YZ plane)
G19 G1 Y10 F1200
G2 Y30 Z0 J10 K0
G1 Y40
G3 Y60 Z0 J10 K0 F6000
G2 Y70 Z0 J5 K0 F3000
G1 Y80
G2 Y105 Z25 J25 K0
G1 Y115
G3 Y155 Z65 J0 K40 F1800
G1 Z80
G3 Y175 Z80 X210 J10 K0 F1500
G1 Y185 F2000
(a full helical turn of 5 mm back 5 mm in X)
G2 Y185 Z80 X205 J5 K0 F3000
(a plunge, a half circle of 5 mm and a line between rapids, then a wider tolerance)
G0 Z85
G1 Z80 F1200
G2 Y195 Z80 J5 K0
G1 Y205
G0 Z85
G64 P0.05
(a dwell after a G18 half circle, and a G18 arc to end the program)
G1 Z80 F2400
G18 G2 X225 Z80 I10 K0
G4 P0.3
G1 X235
G3 X255 Z80 I10 K0 F1800
M2
"""


def splines() -> str:
    """G5.1 quadratic and G5 cubic splines in the XY plane at 20-60 mm/s, which LinuxCNC's task
    runs as biarcs: a chain of curves, a straight G5.1 (its control point on the chord), a G5
    continuing the previous one's end tangent (no I, J), an S and a hook, one in inches."""
    return """\
(nctwin language program: G5 and G5.1 splines)
G21 G17 G90 G94 G40 G49 G80
G64 P0.02
G0 X0 Y0 Z1
G1 Z0 F600
(quadratic splines G5.1: a chain of curves at 20 mm/s)
G5.1 X20 Y0 I10 J10 F1200
G5.1 X40 Y0 I10 J-10
G5.1 X60 Y20 I20 J0
(a straight G5.1: the control point on the chord)
G5.1 X80 Y20 I10 J0
G1 X90
(cubic splines G5, the second continuing the first's end tangent)
G5 X110 Y40 I10 J0 P0 Q-10 F2400
G5 X130 Y20 P10 Q0
(a wide S and a tight hook at 60 mm/s)
G5 X100 Y-10 I-20 J-30 P30 Q-10 F3600
G5.1 X90 Y0 I-10 J-5
G1 X80 Y0
(in inches, at 40 in/min)
G20
G5.1 X2.5 Y-0.5 I-0.5 J-0.5 F40
G21 G0 Z5
M2
"""


def nurbs() -> str:
    """G5.2/G5.3 NURBS in the XY plane at 20-40 mm/s, which LinuxCNC's task runs as biarcs: a
    quadratic wave of weights 1 (order 3, the default), a quarter circle of radius 30 mm (a
    rational quadratic, its middle weight sqrt(2)/2), a cubic (L4) and a quartic (L5) of
    weights 0.5-4."""
    return """\
(nctwin language program: G5.2/G5.3 NURBS)
G21 G17 G90 G94 G40 G49 G80
G64 P0.02
G0 X0 Y0 Z1
G1 Z0 F600
(a quadratic wave, order 3, weights 1, at 20 mm/s)
G5.2 X10 Y20 P1 F1200
X30 Y-20 P1
X50 Y20 P1
X60 Y0 P1
G5.3
G1 X90 Y0
(a quarter circle of radius 30 mm about X60 Y0: the middle weight is cos 45 deg)
G5.2 X90 Y30 P0.7071067811865476
X60 Y30 P1
G5.3
(a cubic, L4, weights 1 to 4, at 40 mm/s)
G5.2 X40 Y50 P1 L4 F2400
X20 Y30 P4
X0 Y60 P1
X-20 Y40 P2
X-10 Y20 P1
G5.3
(a quartic, L5, at 30 mm/s)
G5.2 X-30 Y10 P1 L5 F1800
X-20 Y-20 P3
X0 Y-30 P0.5
X20 Y-20 P2
X10 Y-5 P1
G5.3
G1 X0 Y0
G0 Z5
M2
"""


def tool_pauses() -> str:
    """Words LinuxCNC's task runs only once the motion has stopped, between moves: coolant on
    and off, a program pause (M0), the spindle stopped and started, a tool change with its
    length offset (``T1 M6 G43 H1``), and the short dwells before rapids of LinuxCNC's
    skeleton program (``G4 P.001``)."""
    return """\
(nctwin language program: tool change, pause, spindle, coolant and dwells between moves)
G21 G17 G90 G94 G40 G49 G80
G64 P0.05
G0 X0 Y0 Z10
S1000 M3
G1 Z0 F600
G1 X40 F1800
(coolant on and off between lines)
M8
G1 Y30
M9
G1 X0
(a program pause: the operator's wait is not timed)
M0
G1 Y0
(a tool change with its length offset, the spindle stopped and restarted)
M5
G0 Z20
T1 M6 G43 H1
G4 P.001 G0 X20 Y20 S2000 M3
G4 P.001 G0 Z1
G1 Z0 F600
G1 X60 Y20 F2400
G1 X60 Y-10
(a short dwell before each rapid)
G4 P.001 G0 Z10
G4 P.001 G0 X0 Y0
M5 M9
G49
M2
"""


#: Name -> function returning the program's text.
LANGUAGE_PROGRAMS: dict[str, Callable[[], str]] = {
    "drill_cycles": drill_cycles,
    "cutter_compensation": cutter_compensation,
    "subroutines": subroutines,
    "parametric_curve": parametric_curve,
    "offsets_units": offsets_units,
    "plane_arcs": plane_arcs,
    "splines": splines,
    "nurbs": nurbs,
    "tool_pauses": tool_pauses,
}
