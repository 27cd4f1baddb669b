"""LinuxCNC as the measured machine: run a program on a real NC kernel and record its motion.

LinuxCNC (Debian ``linuxcnc-uspace``) is a widely used CNC control. Its trajectory planner has
look-ahead, blends corners with arcs within the ``G64 P`` tolerance, stops exactly with ``G61``,
and respects per-axis velocity and acceleration limits; it has no jerk limit. :func:`run` records
a program on it and returns the same :class:`~nctwin.motion.Motion` as the virtual kernels.

How a run works
---------------
* The INI and HAL files are generated from a :class:`~nctwin.machine.Machine` and the
  :class:`~nctwin.controls.PlannerControl` of its profile (:func:`ini_text`, :func:`hal_text`):
  trivkins XYZ, servo and trajectory period = the control's ``period_s``,
  ``[AXIS_*]``/``[JOINT_*]`` limits from the axis limits, ``[TRAJ]`` ``MAX_LINEAR_VELOCITY`` =
  ``max_feed_mm_s``, ``MAX_LINEAR_ACCELERATION`` = the largest axis acceleration, no
  ``ARC_BLEND_*`` settings (LinuxCNC's defaults), no homing, start at X0 Y0 Z0, and the startup
  code ``G21 G90 G64 P<blend_tol_mm> Q0`` (the control's; ``G21 G90 G64`` where it is ``inf``).
  A plain ``G64`` (no P) means P0 on LinuxCNC: no tolerance; a ``G64 P`` without Q sets Q = P,
  which turns on its naive-CAM detector. LinuxCNC 2.9 runs the moves before a program's first
  ``G61``/``G64`` as a plain ``G64`` whatever the startup code asks (measured on LinuxCNC's
  ``bracket`` example, see ``data/machines/linuxcnc_sim.toml``), so ``linuxcnc_sim``'s
  tolerance is ``inf``.
* Each run gets its own folder and private namespaces (``unshare``: PID, mount, IPC, network):
  the folder is the instance's ``/tmp`` and ``HOME``, ``/dev/shm`` is a fresh tmpfs. Instances
  never see each other's lock file, shared memory or NML port, and nothing is left behind; when
  the run ends or times out, killing the namespace's first process ends every process in it.
  Namespaces need root (as in CI). If the calling Python process itself is killed, the instance
  runs its program to the end and its folder (``$TMPDIR/nctwin-linuxcnc-*``) stays.
* LinuxCNC runs in POSIX non-realtime mode (no RT kernel; the planner's output is the same) and,
  through libfaketime, ``speed`` times faster than real time.
* The ``DISPLAY`` program is ``_linuxcnc_display.py``, run by the system Python (where LinuxCNC's
  ``linuxcnc`` module lives): it runs the program and records HAL's ``sampler`` (``axis.*.pos-cmd``,
  ``motion.current-vel``, ``motion.program-line``, ``motion.in-position``) every servo period
  with ``halsampler``. It holds the motion (feed and rapid overrides at 0) until the interpreter
  has queued the whole program (or filled the planner's queue), so the planner's look-ahead never
  depends on how fast the interpreter ran: traces repeat bit for bit, at any speed-up up to 5
  and on a busy machine. After a queue buster in the middle of a program (a dwell, an M-code that
  waits) the motion restarts as soon as the next move is queued, as on the real control; such
  programs may not repeat bit for bit. A program pause (``M0``, ``M1``) is resumed at once,
  as if the operator pressed cycle start (``AUTO_RESUME`` at the display's next poll): the
  recorded rest after it, 8-10 ms after an ``M0`` and 130-150 ms after an ``M1`` measured, is
  the recorder's. This module only writes and reads files, so nctwin
  imports without LinuxCNC.

Conventions of the returned motion: ``pos_mm`` is the commanded position (``pos-cmd``), the first
sample is the last one at rest before the tool moves, the last the first one at rest after it
stops (a dwell at the very start or end of a program is not part of the motion), velocities are
backward differences of the positions, and ``block`` is the Toolpath block of the program line
LinuxCNC executes (``motion.program-line``; blend arcs carry the line of a block they join).
``make linuxcnc`` installs LinuxCNC and libfaketime and creates the user :data:`RTAPI_USER`.
"""

from __future__ import annotations

import glob
import json
import math
import os
import pwd
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..checks import check_range
from ..controls import PlannerControl
from ..gcode import LINUXCNC_TOOL_TABLE, GCodeError, complete_tool_table, dump, parse
from ..machine import Machine, ToolTable
from ..motion import Motion
from ..toolpath import MotionKind, Toolpath

__all__ = [
    "LinuxCNCAborted",
    "LinuxCNCError",
    "LinuxCNCUnavailable",
    "Recording",
    "available",
    "hal_text",
    "ini_text",
    "motion_of",
    "record",
    "run",
]

#: Unprivileged user whose uid LinuxCNC gets as ``RTAPI_UID`` when run as root.
RTAPI_USER = "linuxcnc-rt"
#: The LinuxCNC start script and the sampler reader.
LINUXCNC = "/usr/bin/linuxcnc"
HALSAMPLER = "/usr/bin/halsampler"
#: libfaketime's multi-threaded preload library (Debian ``libfaketime``), any architecture.
FAKETIME_GLOB = "/usr/lib/*/faketime/libfaketimeMT.so.1"
#: ``[TRAJ] DEFAULT_LINEAR_VELOCITY`` (jogging and MDI default; programs set their own F).
DEFAULT_LINEAR_VELOCITY_MM_S = 50.0
#: Soft limits of every axis (mm): the profiles give no travel, so wide enough for any program.
TRAVEL_MM = 10000.0
#: Depth of the sampler's FIFO (samples); ``halsampler`` empties it while the program runs.
SAMPLER_DEPTH = 200000
#: Where the instance sees its own folder (its private ``/tmp``).
INSTANCE_DIR = "/tmp"

_DISPLAY = Path(__file__).with_name("_linuxcnc_display.py")


class LinuxCNCError(GCodeError):
    """A program LinuxCNC rejected, with LinuxCNC's message (and its line, when it names one)."""


class LinuxCNCUnavailable(RuntimeError):
    """LinuxCNC cannot run here (not installed, not root, user missing); says what to do."""


class LinuxCNCAborted(RuntimeError):
    """LinuxCNC stopped a program before its end without an error for the program itself (e.g.
    ``USRMOT: ERROR: command timeout`` when the machine is too busy for the speed-up)."""


def available() -> str | None:
    """Why LinuxCNC cannot run here, or None if it can."""
    for exe in (LINUXCNC, HALSAMPLER, "/usr/bin/python3", "/usr/sbin/ip"):
        if not os.path.exists(exe):
            return f"{exe} is missing: run `make linuxcnc`"
    if not _faketime_lib():
        return f"libfaketime ({FAKETIME_GLOB}) is missing: run `make linuxcnc`"
    if shutil.which("unshare") is None:
        return "unshare (util-linux) is missing"
    if os.geteuid() != 0:
        return "LinuxCNC runs in private namespaces (unshare), which needs root"
    try:
        pwd.getpwnam(RTAPI_USER)
    except KeyError:
        return f"user {RTAPI_USER!r} (RTAPI_UID) is missing: run `make linuxcnc`"
    return None


def _faketime_lib() -> str | None:
    found = sorted(glob.glob(FAKETIME_GLOB))
    return found[0] if found else None


def _limits(machine: Machine, control: PlannerControl) -> None:
    """Raise ValueError where the machine or its control asks what LinuxCNC cannot do."""
    if any(j != float("inf") for j in machine.axis_max_jerk_mm_s3):
        raise ValueError(
            f"axis_max_jerk_mm_s3 = {machine.axis_max_jerk_mm_s3!r} is out of range for "
            "LinuxCNC: allowed (inf, inf, inf) (its planner has no jerk limit)"
        )
    if machine.rapid_feed_mm_s != machine.max_feed_mm_s:
        raise ValueError(
            f"rapid_feed_mm_s = {machine.rapid_feed_mm_s!r} is out of range for LinuxCNC: "
            f"allowed max_feed_mm_s = {machine.max_feed_mm_s!r} (one MAX_LINEAR_VELOCITY)"
        )
    period_ns = control.period_s * 1e9
    if abs(period_ns - round(period_ns)) > 1e-6:
        raise ValueError(
            f"period_s = {control.period_s!r} is out of range for LinuxCNC: allowed whole "
            "nanoseconds"
        )


def ini_text(machine: Machine, control: PlannerControl) -> str:
    """The INI file of a LinuxCNC instance for ``machine`` under ``control`` (see the module
    docstring).

    Raises
    ------
    ValueError
        If the profile has a finite jerk limit, a rapid feed other than its maximum feed, or a
        period that is not a whole number of nanoseconds.
    """
    _limits(machine, control)
    d = INSTANCE_DIR
    vmax, amax = machine.axis_max_velocity_mm_s, machine.axis_max_acceleration_mm_s2
    lines = [
        "# generated by nctwin.kernel.linuxcnc from machine profile " + machine.name,
        "[EMC]",
        "VERSION = 1.1",
        f"MACHINE = nctwin-{machine.name}",
        "[DISPLAY]",
        f"DISPLAY = {d}/display.py",
        "[TASK]",
        "TASK = milltask",
        f"CYCLE_TIME = {control.period_s!r}",
        "[RS274NGC]",
        f"PARAMETER_FILE = {d}/sim.var",
        f"RS274NGC_STARTUP_CODE = G21 G90 {_startup_mode(control.blend_tol_mm)}",
        "[EMCMOT]",
        "EMCMOT = motmod",
        "COMM_TIMEOUT = 1.0",
        f"SERVO_PERIOD = {round(control.period_s * 1e9)}",
        "[EMCIO]",
        "EMCIO = io",
        "CYCLE_TIME = 0.1",
        f"TOOL_TABLE = {d}/tool.tbl",
        "[HAL]",
        f"HALFILE = {d}/sim.hal",
        "[KINS]",
        "KINEMATICS = trivkins coordinates=XYZ",
        "JOINTS = 3",
        "[TRAJ]",
        "COORDINATES = X Y Z",
        "LINEAR_UNITS = mm",
        "ANGULAR_UNITS = degree",
        f"DEFAULT_LINEAR_VELOCITY = {DEFAULT_LINEAR_VELOCITY_MM_S!r}",
        f"MAX_LINEAR_VELOCITY = {machine.max_feed_mm_s!r}",
        f"MAX_LINEAR_ACCELERATION = {max(amax)!r}",
        "NO_FORCE_HOMING = 1",
    ]
    for i, axis in enumerate("XYZ"):
        limits = [
            f"MAX_VELOCITY = {vmax[i]!r}",
            f"MAX_ACCELERATION = {amax[i]!r}",
            f"MIN_LIMIT = {-TRAVEL_MM!r}",
            f"MAX_LIMIT = {TRAVEL_MM!r}",
        ]
        lines += [f"[AXIS_{axis}]", *limits]
        lines += [f"[JOINT_{i}]", "TYPE = LINEAR", "HOME = 0.0", *limits]
        lines += [f"FERROR = {TRAVEL_MM!r}", f"MIN_FERROR = {TRAVEL_MM!r}", "HOME_SEQUENCE = 0"]
    return "\n".join(lines) + "\n"


def _startup_mode(blend_tol_mm: float) -> str:
    """The startup code's path-control words: ``G64 P<tol> Q0``, or a plain ``G64`` for an
    infinite tolerance."""
    return "G64" if math.isinf(blend_tol_mm) else f"G64 P{blend_tol_mm!r} Q0"


def hal_text() -> str:
    """The HAL file: motion, a simulated machine (feedback = command) and the sampler.

    Sampler columns: X, Y, Z ``pos-cmd`` (mm), ``motion.current-vel`` (mm/s),
    ``motion.program-line`` and ``motion.in-position``; the sampler runs after the motion
    controller in every servo period.
    """
    lines = [
        "loadrt [KINS]KINEMATICS",
        "loadrt [EMCMOT]EMCMOT servo_period_nsec=[EMCMOT]SERVO_PERIOD num_joints=[KINS]JOINTS",
        f"loadrt sampler depth={SAMPLER_DEPTH} cfg=ffffsb",
        "addf motion-command-handler servo-thread",
        "addf motion-controller servo-thread",
        "addf sampler.0 servo-thread",
    ]
    lines += [f"net j{i}pos joint.{i}.motor-pos-cmd => joint.{i}.motor-pos-fb" for i in range(3)]
    signals = ["axis.x.pos-cmd", "axis.y.pos-cmd", "axis.z.pos-cmd", "motion.current-vel"]
    signals += ["motion.program-line", "motion.in-position"]
    lines += [f"net rec{k} {pin} => sampler.0.pin.{k}" for k, pin in enumerate(signals)]
    lines += [
        "net estop-loop iocontrol.0.user-enable-out => iocontrol.0.emc-enable-in",
        "net tool-prep-loop iocontrol.0.tool-prepare => iocontrol.0.tool-prepared",
        "net tool-change-loop iocontrol.0.tool-change => iocontrol.0.tool-changed",
    ]
    return "\n".join(lines) + "\n"


#: The shell run as first process of the private namespaces: the instance's folder becomes its
#: /tmp (and HOME), /dev/shm a fresh tmpfs, loopback up for NML.
_NAMESPACE_SCRIPT = f"""set -eu
mount --bind "$1" {INSTANCE_DIR}
mount -t tmpfs tmpfs /dev/shm
ip link set lo up
cd {INSTANCE_DIR}
exec {LINUXCNC} -r {INSTANCE_DIR}/sim.ini
"""


@dataclass(frozen=True, eq=False)
class Recording:
    """What the sampler recorded every servo period, trimmed to the motion.

    Parameters
    ----------
    pos_mm : ndarray, shape (n, 3)
        ``axis.{x,y,z}.pos-cmd``.
    current_vel_mm_s : ndarray, shape (n,)
        ``motion.current-vel`` (the planner's path speed).
    program_line : ndarray of int64, shape (n,)
        ``motion.program-line``.
    in_position : ndarray of bool, shape (n,)
        ``motion.in-position``.
    period_s : float
        Servo period.
    log : str
        LinuxCNC's console output.
    """

    pos_mm: np.ndarray
    current_vel_mm_s: np.ndarray
    program_line: np.ndarray
    in_position: np.ndarray
    period_s: float
    log: str


def _check_run_args(timeout_s: float, speed: float) -> None:
    check_range("timeout_s", timeout_s, 0.0, float("inf"), low_open=True, high_open=True)
    check_range("speed", speed, 1.0, 20.0)


def record(
    program: str,
    machine: Machine,
    control: PlannerControl,
    *,
    timeout_s: float = 600.0,
    speed: float = 5,
    tool_table: ToolTable | None = None,
) -> Recording:
    """Run a program on a fresh LinuxCNC instance and return what the sampler recorded.

    Parameters
    ----------
    program : str
        G-code text as LinuxCNC reads it (``M2`` is appended if the program has no end).
    machine : Machine
    control : PlannerControl
        The period and the startup tolerance (:func:`ini_text`).
    timeout_s : float
        Wall-clock limit of the whole run (start-up, program, shut-down); the instance is
        killed when it is reached.
    speed : float
        Speed-up over real time through libfaketime, in [1, 20]. Up to 5 the traces equal
        those of real time; faster shifts start-up and risks a starved planner queue.
    tool_table : ToolTable, optional
        The machine's tools (a profile's ``tool_table``), written to the instance's
        ``tool.tbl``; default :data:`~nctwin.gcode.LINUXCNC_TOOL_TABLE`, tool 1 of size 0. The
        program's other tools are added with size 0 where no size is needed
        (:func:`~nctwin.gcode.complete_tool_table`).

    Raises
    ------
    LinuxCNCError
        If LinuxCNC rejects the program (its message, and its line when it names one).
    LinuxCNCUnavailable
        If LinuxCNC cannot run here (see :func:`available`).
    TimeoutError
        If the run takes longer than ``timeout_s``, or LinuxCNC does not carry out a command
        within 10 s.
    LinuxCNCAborted
        If LinuxCNC's motion controller reports an error (a busy machine at a high speed-up).
    """
    _check_run_args(timeout_s, speed)
    ini = ini_text(machine, control)
    why = available()
    if why:
        raise LinuxCNCUnavailable(f"LinuxCNC cannot run: {why}")
    if not re.search(r"^\s*[^(;]*\b[Mm]0*(?:2|30)\b", program, flags=re.MULTILINE):
        program = program.rstrip("\n") + "\nM2\n"
    folder = Path(tempfile.mkdtemp(prefix="nctwin-linuxcnc-"))
    try:
        folder.chmod(0o1777)  # it is the instance's /tmp
        files = {
            "sim.ini": ini,
            "sim.hal": hal_text(),
            # the machine's tools (or nctwin's own) and the program's others, of size 0
            "tool.tbl": complete_tool_table(
                LINUXCNC_TOOL_TABLE if tool_table is None else tool_table.text, program
            ),
            "program.ngc": program,
            "display.py": _DISPLAY.read_text(),
        }
        for name, text in files.items():
            (folder / name).write_text(text)
        (folder / "display.py").chmod(0o755)
        env = {
            "PATH": "/usr/sbin:/usr/bin:/sbin:/bin",
            "HOME": INSTANCE_DIR,
            "LANG": "C.UTF-8",
            "RTAPI_UID": str(pwd.getpwnam(RTAPI_USER).pw_uid),
            "LD_PRELOAD": _faketime_lib(),
            "FAKETIME": f"+0 x{speed:g}",
        }
        cmd = ["unshare", "--pid", "--kill-child", "--mount-proc", "--ipc", "--net", "--mount"]
        cmd += ["sh", "-c", _NAMESPACE_SCRIPT, "sh", str(folder)]
        with (folder / "console.log").open("w") as log:
            try:
                subprocess.run(
                    cmd, env=env, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT,
                    timeout=timeout_s, check=False,
                )  # fmt: skip
            except subprocess.TimeoutExpired:
                timed_out = True
            else:
                timed_out = False
        console = (folder / "console.log").read_text(errors="replace")
        if timed_out:
            raise TimeoutError(
                f"LinuxCNC did not finish the program within timeout_s = {timeout_s!r} s; the "
                "instance was killed. The end of its output:\n" + console[-2000:]
            )
        result_file = folder / "result.json"
        if not result_file.exists():
            raise LinuxCNCUnavailable(
                "LinuxCNC did not run the program; its output:\n" + console[-4000:]
            )
        result = json.loads(result_file.read_text())
        if "stuck" in result:
            raise TimeoutError(f"{result['stuck']}; the instance was shut down")
        if not result["ok"]:
            raise _rejected(result["message"], program)
        aborted = [ln for ln in console.splitlines() if "USRMOT: ERROR" in ln]
        if aborted:
            raise LinuxCNCAborted(
                f"LinuxCNC aborted the program ({aborted[0].strip()}): the machine was too busy "
                f"for speed = {speed!r}; run again, or with a lower speed"
            )
        samples = _read_samples(folder / "samples.txt")
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return _trim(samples, control.period_s, console)


def _rejected(message: str, program: str) -> LinuxCNCError:
    """LinuxCNC's message as an error naming the line it cites (0 where it names none)."""
    m = re.search(r"\bline (\d+)", message)
    line = int(m.group(1)) if m else 0
    lines = program.splitlines()
    text = lines[line - 1] if 0 < line <= len(lines) else ""
    return LinuxCNCError(line, text, f"LinuxCNC: {message.strip()}", "program.ngc")


def _read_samples(path: Path) -> np.ndarray:
    """halsampler's tagged lines as an array (n, 7): tag, x, y, z, vel, line, in-position."""
    rows = [ln.split() for ln in path.read_text().splitlines()]
    rows = [r for r in rows if len(r) == 7]  # the reader may stop inside the last line
    data = np.array(rows, dtype=np.float64).reshape(-1, 7)
    if len(data) and np.any(np.diff(data[:, 0]) != 1):
        raise LinuxCNCUnavailable(
            "samples were lost (the sampler's FIFO overran): the machine is too busy for this "
            "speed; use a lower speed"
        )
    return data


def _trim(data: np.ndarray, period_s: float, console: str) -> Recording:
    """Keep the samples from the last one at rest before the motion to the first one after."""
    pos = data[:, 1:4]
    moving = np.flatnonzero(np.any(np.diff(pos, axis=0) != 0, axis=1))
    lo, hi = (moving[0], moving[-1] + 2) if len(moving) else (0, min(1, len(pos)))
    return Recording(
        pos_mm=pos[lo:hi],
        current_vel_mm_s=data[lo:hi, 4],
        program_line=data[lo:hi, 5].astype(np.int64),
        in_position=data[lo:hi, 6] != 0,
        period_s=period_s,
        log=console,
    )


def run(
    toolpath_or_program: Toolpath | str,
    machine: Machine,
    control: PlannerControl,
    *,
    timeout_s: float = 600.0,
    speed: float = 5,
    tool_table: ToolTable | None = None,
) -> Motion:
    """Record a tool path (or program text) on LinuxCNC.

    Parameters
    ----------
    toolpath_or_program : Toolpath or str
        A tool path (written with :func:`nctwin.gcode.dump`), or G-code text, which LinuxCNC
        runs as written and :func:`nctwin.gcode.parse` reads for the block numbers.
    machine : Machine
        Its axis limits and maximum feed make the INI (:func:`ini_text`).
    control : PlannerControl
        Its period and blending tolerance too.
    timeout_s, speed : float
        See :func:`record`.
    tool_table : ToolTable, optional
        See :func:`record`; :func:`nctwin.gcode.parse` reads the text with it too.

    Returns
    -------
    Motion
        Samples every servo period from rest to rest; ``block`` indexes the Toolpath's blocks
        (of ``parse(program)`` for text). A program without motion or dwell gives one sample at
        X0 Y0 Z0 without starting LinuxCNC.

    Raises
    ------
    GCodeError
        If nctwin cannot read the program text.
    LinuxCNCError
        If LinuxCNC rejects the program.
    LinuxCNCUnavailable, TimeoutError
        See :func:`record`.
    LinuxCNCAborted
        If the recorded motion does not reach the program's last move.
    """
    if isinstance(toolpath_or_program, Toolpath):
        text = dump(toolpath_or_program)
    elif isinstance(toolpath_or_program, str):
        text = toolpath_or_program
    else:
        raise ValueError(
            f"toolpath_or_program = {type(toolpath_or_program).__name__} is not allowed: "
            "allowed a Toolpath or G-code text (str)"
        )
    _check_run_args(timeout_s, speed)
    tp = parse(text, tool_table=tool_table)
    if not ((tp.lengths_mm > 0) | (tp.kind == MotionKind.DWELL)).any():
        # nothing moves: one sample at LinuxCNC's start position, without starting it
        z = np.zeros((1, 3))
        return Motion(np.zeros(1), z, z, np.zeros(1, dtype=np.int64), control.period_s)
    rec = record(text, machine, control, timeout_s=timeout_s, speed=speed, tool_table=tool_table)
    motion = motion_of(rec, tp)
    last = int(np.flatnonzero((tp.lengths_mm > 0) | (tp.kind == MotionKind.DWELL))[-1])
    if motion.block[-1] < last or not np.allclose(motion.pos_mm[-1], tp.end_mm[last], atol=1e-6):
        raise LinuxCNCAborted(
            f"LinuxCNC stopped at program line {int(rec.program_line[-1])}, before the program's "
            f"last move (line {int(tp.line[last])}), at {motion.pos_mm[-1].round(4).tolist()} mm"
        )
    return motion


def motion_of(rec: Recording, toolpath: Toolpath) -> Motion:
    """A recording as :class:`~nctwin.motion.Motion` of ``toolpath`` (the program's blocks).

    The block of a sample is the last block whose source line is at most the program line
    LinuxCNC reports (lines without motion map to the block before them), made non-decreasing.
    Where the blocks' lines are not in order (a subroutine's lines run again at every call),
    the program is followed forward: a sample goes to the first run of blocks at or after the
    previous sample's block that has its line (its last block, as above), and a line that no
    later block has keeps the previous block.
    """
    n = len(rec.pos_mm)
    vel = np.zeros((n, 3))
    vel[1:] = np.diff(rec.pos_mm, axis=0) / rec.period_s
    if not len(toolpath):
        block = np.zeros(n, dtype=np.int64)
    elif np.all(np.diff(toolpath.line) >= 0):
        block = np.searchsorted(toolpath.line, rec.program_line, side="right") - 1
        block = np.maximum.accumulate(np.clip(block, 0, len(toolpath) - 1))
    else:
        block = _follow_lines(toolpath.line, rec.program_line)
    t = np.arange(n) * rec.period_s
    return Motion(t, rec.pos_mm, vel, block.astype(np.int64), rec.period_s)


def _follow_lines(block_line: np.ndarray, sample_line: np.ndarray) -> np.ndarray:
    """The block of each sample (see :func:`motion_of`) for blocks whose lines (B,) are not in
    order; ``sample_line`` (n,) are the lines LinuxCNC reported. Returns (n,) block indices."""
    # runs of equal lines among the blocks: their first and last block and their line
    first = np.flatnonzero(np.r_[True, block_line[1:] != block_line[:-1]])
    last = np.r_[first[1:] - 1, len(block_line) - 1]
    runs_of: dict[int, np.ndarray] = {}
    for line in np.unique(block_line):
        runs_of[int(line)] = np.flatnonzero(block_line[first] == line)
    changes = np.flatnonzero(np.r_[True, sample_line[1:] != sample_line[:-1]])
    run = 0
    run_of_change = np.empty(len(changes), dtype=np.int64)
    for k, i in enumerate(changes):
        runs = runs_of.get(int(sample_line[i]))
        if runs is not None:
            j = np.searchsorted(runs, run)
            if j < len(runs):
                run = int(runs[j])
        run_of_change[k] = run
    counts = np.diff(np.r_[changes, len(sample_line)])
    return last[np.repeat(run_of_change, counts)]
