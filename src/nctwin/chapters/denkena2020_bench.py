"""The simulated test bench of the Denkena chapter: the milling centre with direct linear
drives on which the processes and air moves of :mod:`nctwin.chapters.denkena2020` are "measured".

:func:`run_processes` interpolates each process, computes its milling forces
(:mod:`nctwin.physics.cutting`) and runs the drives (:mod:`nctwin.physics.drives`) in batches
through :func:`nctwin.runner.run_tasks`, with a cache keyed by a hash of every parameter
(:mod:`nctwin.cache`); :func:`run_air_moves` records the air moves the model is fitted on.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass

import numpy as np

from ..cache import atomic_savez, cache_path, content_key
from ..kernel.fir import FirFilter
from ..physics import cutting, drives
from ..runner import run_tasks

__all__ = [
    "DIRECTIONS",
    "TOOL",
    "AirMoves",
    "Process",
    "Recorded",
    "Windows",
    "chatter_regeneration_mm",
    "process_windows",
    "run_air_moves",
    "run_processes",
]


#: Straight feed directions (unit vectors in XY).
DIRECTIONS = {
    "+x": (1.0, 0.0),
    "-x": (-1.0, 0.0),
    "+y": (0.0, 1.0),
    "-y": (0.0, -1.0),
    "+x+y": (0.7071067811865476, 0.7071067811865476),
    "-x-y": (-0.7071067811865476, -0.7071067811865476),
    "+x-y": (0.7071067811865476, -0.7071067811865476),
    "-x+y": (-0.7071067811865476, 0.7071067811865476),
}


#: The end mill of every process.
TOOL = cutting.EndMill()


@dataclass(frozen=True)
class Process:
    """One milling process.

    Parameters
    ----------
    index : int
    kind : {"side", "groove", "pocket", "ramp"}
    feed_direction : str
        A key of :data:`DIRECTIONS`, ``"ccw"`` or ``"-y/+z"``.
    ae_mm, ap_mm, vf_mm_min, n_rpm : float
        Table 1 parameters (the ramp's ``ap_mm`` is its largest depth; it climbs out to 0).
    start_mm : tuple of float
        Tool centre at the start.
    semi_stable : bool
        The tool vibrates against the workpiece normal to the feed while cutting
        (:func:`chatter_regeneration_mm`).
    chatter_hz, chatter_amplitude_mm : float
        Frequency and amplitude of that vibration (0 when stable).
    test : bool
        In the 21-process test set.
    """

    index: int
    kind: str
    feed_direction: str
    ae_mm: float
    ap_mm: float
    vf_mm_min: float
    n_rpm: float
    start_mm: tuple[float, float, float]
    semi_stable: bool
    chatter_hz: float
    chatter_amplitude_mm: float
    test: bool


def _segment(
    length_mm: float, speed_mm_s: float, dt: float, t1_s: float = 0.06, t2_s: float = 0.015
):
    """Arc length (n,) of one segment travelled at ``speed_mm_s`` from rest to rest: a
    rectangular velocity pulse, held at rest outside its span, through the interpolator's FIR
    filter (:class:`nctwin.kernel.fir.FirFilter`, jerk-limited), then integrated.
    """
    pulse = np.full(max(round(length_mm / speed_mm_s / dt), 1), speed_mm_s)
    held = np.zeros((3, len(pulse) + 2))
    held[0, 1:-1] = pulse * length_mm / (pulse.sum() * dt)
    vel = FirFilter(t1_s, t2_s, dt).apply(held)[0]
    return np.concatenate([[0.0], np.cumsum(vel) * dt])


def _hold(n_total: int, *parts: np.ndarray) -> np.ndarray:
    out = np.concatenate(parts)
    if len(out) > n_total:
        raise ValueError(f"trajectory of {len(out)} steps is longer than the run ({n_total})")
    return np.concatenate([out, np.repeat(out[-1:], n_total - len(out), axis=0)])


def _trajectory(p: Process, n_steps: int, dt: float):
    """Set points (n, 3), tool path tangent angle (n,), engagement weight (n,), depth (n,),
    segment flag (n,): 0 air, 1 slot, 2 ae-engagement, 3 plunge."""
    v = p.vf_mm_min / 60.0
    start = np.array(p.start_mm)
    t_run = n_steps * dt
    r = TOOL.radius_mm
    lead = 0.6  # s of air feed before the material
    if p.kind in ("side", "groove", "ramp"):
        u = (
            np.array([*DIRECTIONS[p.feed_direction], 0.0])
            if p.kind != "ramp"
            else np.array([0.0, -1.0, 0.0])
        )
        length = v * (t_run - 0.6)
        sigma = _segment(length, v, dt)
        pos = start + sigma[:, None] * u
        s_in, s_out = v * lead, length - v * 0.5
        weight = np.clip((sigma - s_in) / r, 0, 1) * np.clip((s_out - sigma) / r, 0, 1)
        depth = np.full_like(sigma, p.ap_mm)
        if p.kind == "ramp":  # climbs +z: depth ap -> 0 over the cut
            frac = np.clip((sigma - s_in) / (s_out - s_in), 0, 1)
            depth = p.ap_mm * (1 - frac)
            pos[:, 2] += p.ap_mm * frac
        angle = np.full_like(sigma, np.arctan2(u[1], u[0]))
        flag = np.where(weight > 0, 1 if p.ae_mm >= TOOL.diameter_mm else 2, 0)
        parts = (pos, angle, weight, depth, flag)
    else:  # pocket: plunge, slot out to the circle, ccw circle(s) in ae engagement
        v_plunge = v / 2.0
        s1 = _segment(p.ap_mm, v_plunge, dt)
        t_left = t_run - len(s1) * dt - 0.6
        rc = float(np.clip(v * t_left * 0.8 / (2 * np.pi + 1), 3.0, 12.0))
        s2 = _segment(rc, v, dt)
        s3 = _segment(v * (t_left - len(s2) * dt - 0.2), v, dt)
        c0 = start - [0, 0, p.ap_mm]
        p1 = start + np.outer(s1, [0, 0, -1.0])
        p2 = c0 + np.outer(s2, [1.0, 0, 0])
        ang = s3 / rc
        p3 = c0 + rc * np.stack([np.cos(ang), np.sin(ang), 0 * ang], axis=1)
        pos = np.concatenate([p1, p2, p3])
        angle = np.concatenate([np.full(len(s1), 0.0), np.zeros(len(s2)), ang + np.pi / 2])
        weight = np.concatenate([np.clip(s1 / r, 0, 1), np.ones(len(s2)), np.ones(len(s3))])
        depth = np.concatenate([s1, np.full(len(s2) + len(s3), p.ap_mm)])
        flag = np.concatenate([np.full(len(s1), 3), np.ones(len(s2)), np.full(len(s3), 2)])
        parts = (pos, angle, weight, depth, flag)
    return tuple(_hold(n_steps, a) for a in parts)


def chatter_regeneration_mm(p: Process, t_s: np.ndarray) -> np.ndarray:
    """The regenerative chip of a semi-stable cut (:func:`nctwin.physics.cutting.tool_forces`).

    The tool vibrates against the workpiece normal to the feed (:math:`y'`) in a bounded limit
    cycle near the tool-slide mode, beating slowly as a semi-stable process does,

    .. math:: y'(t) = A \\, \\tfrac12 \\left(1 + \\sin(2\\pi \\cdot 0.7\\,t + i)\\right)
              \\sin(2\\pi f_c t),

    and each tooth cuts the surface the previous tooth left one tooth period :math:`T = 60 /
    (N n)` earlier: :math:`\\Delta y' = y'(t) - y'(t - T)`. The force this adds at :math:`f_c`
    reaches the slides through their compliance (:mod:`nctwin.physics.drives`), near its
    resonance, so the vibration shows in the velocity and current of the axis normal to the feed.

    Parameters
    ----------
    p : Process
        ``chatter_hz`` :math:`f_c`, ``chatter_amplitude_mm`` :math:`A`, ``index`` :math:`i`.
    t_s : ndarray, shape (T,)

    Returns
    -------
    ndarray, shape (T, 2)
        :math:`(\\Delta x', \\Delta y')`; zeros when the cut is stable.
    """
    out = np.zeros((len(t_s), 2))
    if p.semi_stable:
        period = 60.0 / (TOOL.teeth * p.n_rpm)

        def y(t):
            env = 0.5 * (1 + np.sin(2 * np.pi * 0.7 * t + p.index))
            return p.chatter_amplitude_mm * env * np.sin(2 * np.pi * p.chatter_hz * t)

        out[:, 1] = y(t_s) - y(t_s - period)
    return out


def _process_signals(p: Process, n_steps: int, dt: float):
    """Set points (pos, vel, acc), force on the workpiece (n, 3), torque (n,), rpm (n,)."""
    pos, angle, weight, depth, flag = _trajectory(p, n_steps, dt)
    vel = np.gradient(pos, dt, axis=0)
    acc = np.gradient(vel, dt, axis=0)
    t = np.arange(n_steps) * dt
    tooth_hz = TOOL.teeth * p.n_rpm / 60.0
    fz = np.linalg.norm(vel[:, :2], axis=1) / tooth_hz
    regen = chatter_regeneration_mm(p, t)
    force = np.zeros((n_steps, 3))
    torque = np.zeros(n_steps)
    for code, ae in ((1, TOOL.diameter_mm), (2, p.ae_mm)):
        on = flag == code
        if not on.any():
            continue
        mode = "down"
        st, ex = cutting.immersion(min(ae, TOOL.diameter_mm), TOOL.radius_mm, mode)
        f, tq = cutting.tool_forces(
            t[on],
            spindle_rpm=p.n_rpm,
            feed_per_tooth_mm=fz[on],
            ap_mm=depth[on],
            phi_start_rad=st,
            phi_exit_rad=ex,
            tool=TOOL,
            regeneration_mm=regen[on],
        )
        force[on] = cutting.workpiece_forces(f * weight[on, None], angle[on])
        torque[on] = tq * weight[on]
    plunge = flag == 3
    ax_f, ax_t = cutting.plunge_forces(np.clip(-vel[plunge, 2], 0, None) / tooth_hz, tool=TOOL)
    force[plunge, 2] = -ax_f * weight[plunge]
    torque[plunge] = ax_t * weight[plunge]
    return pos, vel, acc, force, torque, np.full(n_steps, p.n_rpm)


@dataclass(frozen=True, eq=False)
class Windows:
    """Where each recorded sample lies: in the cut, moving, at a reversal (set points).

    Parameters
    ----------
    cutting : ndarray of bool, shape (P, R)
        The tool is in the material (engagement weight > 0, or plunging).
    moving : ndarray of bool, shape (P, R, 3)
        The axis' set-point velocity is not zero (else the axis stands still).
    reversal : ndarray of bool, shape (P, R, 3)
        Within ``reversal_s`` of a sign change of the axis' set-point velocity while cutting.
    """

    cutting: np.ndarray
    moving: np.ndarray
    reversal: np.ndarray


def process_windows(
    processes: list[Process],
    machine: drives.FeedDriveMachine,
    *,
    duration_s: float,
    reversal_s: float = 0.1,
) -> Windows:
    """The scoring windows of every process, on the recorded samples (every
    ``machine.decimation``-th servo step, from the first).

    Parameters
    ----------
    processes : list of Process
    machine : FeedDriveMachine
    duration_s : float
        Length of every run, as in :func:`run_processes`.
    reversal_s : float
        Half width of a reversal window (s), > 0.

    Returns
    -------
    Windows
    """
    if not reversal_s > 0.0:
        raise ValueError(f"reversal_s = {reversal_s!r} is out of range: allowed > 0")
    dt = 1.0 / machine.servo_rate_hz
    n = round(duration_s * machine.servo_rate_hz)
    half = round(reversal_s * machine.record_rate_hz)
    cutting, moving, reversal = [], [], []
    for p in processes:
        pos, _, weight, _, flag = _trajectory(p, n, dt)
        vel = np.gradient(pos, dt, axis=0)[:: machine.decimation]
        cut = ((weight > 0) & (flag > 0))[:: machine.decimation]
        flips = np.zeros(vel.shape, dtype=bool)
        flips[1:] = vel[1:] * vel[:-1] < 0
        near = np.stack([np.convolve(f, np.ones(2 * half + 1), "same") > 0 for f in flips.T], 1)
        cutting.append(cut)
        moving.append(np.abs(vel) > 1e-9)
        reversal.append(near & cut[:, None])
    return Windows(np.array(cutting), np.array(moving), np.array(reversal))


@dataclass(frozen=True, eq=False)
class Recorded:
    """What the controller and the dynamometer recorded for every process.

    Parameters
    ----------
    processes : list of Process
    t_s : ndarray, shape (R,)
    inputs : ndarray, shape (P, R, 14)
        :data:`INPUT_NAMES`.
    force_n : ndarray, shape (P, R, 3)
        Dynamometer (noise, 300 Hz low-pass), sampled with the controller.
    seconds : float
        Wall time of the simulation (when the cache was made).
    """

    processes: list[Process]
    t_s: np.ndarray
    inputs: np.ndarray
    force_n: np.ndarray
    seconds: float


def _machine_key(machine: drives.FeedDriveMachine) -> dict:
    return asdict(machine)


def _batch(processes: list[Process], machine, duration_s: float, seed: int):
    dt = 1.0 / machine.servo_rate_hz
    n = round(duration_s * machine.servo_rate_hz)
    sig = [_process_signals(p, n, dt) for p in processes]
    pos, vel, acc, force, torque, rpm = (np.stack(a) for a in zip(*sig, strict=True))
    rng = np.random.default_rng([seed, processes[0].index])
    rec = drives.simulate_drives(pos, vel, acc, force, machine, rng)
    speed, s_current = drives.spindle_signals(torque, rpm, machine, rng)
    dyn = drives.dynamometer(force, machine, rng)
    inputs = np.concatenate(
        [
            rec.pos_mm,
            rec.vel_mm_s,
            rec.acc_mm_s2,
            rec.current_a,
            speed[..., None],
            s_current[..., None],
        ],
        axis=2,
    )
    return rec.t_s, inputs, dyn


def run_processes(
    processes: list[Process],
    machine: drives.FeedDriveMachine,
    *,
    duration_s: float,
    seed: int,
    batch_size: int = 46,
    n_jobs: int = 2,
) -> Recorded:
    """Simulate and record every process (cached).

    Parameters
    ----------
    processes : list of Process
    machine : FeedDriveMachine
    duration_s : float
        Length of every run (air approach, cut, air exit, stop), > 2 s.
    seed : int
        Recording noise.
    batch_size : int
        Processes the drive loop runs together (vectorised).
    n_jobs : int
        joblib workers over batches.

    Returns
    -------
    Recorded
    """
    if not duration_s > 2.0:
        raise ValueError(f"duration_s = {duration_s!r} is out of range: allowed > 2")
    key = {
        "processes": [asdict(p) for p in processes],
        "machine": _machine_key(machine),
        "duration_s": duration_s,
        "seed": seed,
        "batch_size": batch_size,
        "version": 4,
    }
    path = cache_path("denkena2020", "processes", content_key(key), ".npz")
    if path.exists():
        with np.load(path) as d:
            return Recorded(processes, d["t_s"], d["inputs"], d["force_n"], float(d["seconds"]))
    t0 = time.perf_counter()
    batches = [processes[i : i + batch_size] for i in range(0, len(processes), batch_size)]
    out = run_tasks(_batch, ((b, machine, duration_s, seed) for b in batches), n_jobs=n_jobs)
    t_s = out[0][0]
    inputs = np.concatenate([o[1] for o in out])
    force = np.concatenate([o[2] for o in out])
    seconds = time.perf_counter() - t0
    atomic_savez(path, t_s=t_s, inputs=inputs, force_n=force, seconds=seconds)
    return Recorded(processes, t_s, inputs, force, seconds)


@dataclass(frozen=True, eq=False)
class AirMoves:
    """The air moves the model is fitted on, as recorded (no cutting).

    Parameters
    ----------
    kind : ndarray of str, shape (B,)
        ``"line+"``, ``"line-"`` (step 1-2), ``"const"`` (step 3), ``"accel"`` (step 4).
    speed_mm_s : ndarray, shape (B,)
        Programmed velocity of the ``"line"`` and ``"const"`` runs (signed).
    pos_mm, vel_mm_s, acc_mm_s2, current_a : ndarray, shape (B, R, 3)
    """

    kind: np.ndarray
    speed_mm_s: np.ndarray
    pos_mm: np.ndarray
    vel_mm_s: np.ndarray
    acc_mm_s2: np.ndarray
    current_a: np.ndarray


def run_air_moves(
    machine: drives.FeedDriveMachine,
    *,
    seed: int,
    travel_mm: tuple[float, float] = (20.0, 280.0),
    line_speed_mm_s: float = 40.0,
    speeds_mm_s: tuple[float, ...] = tuple(np.geomspace(0.3, 100.0, 14).round(3)),
    accel_speeds_mm_s: tuple[float, ...] = (50.0, 100.0, 150.0),
    accel_mm: float = 80.0,
    duration_s: float = 7.5,
) -> AirMoves:
    """Record the paper's air moves (all three axes move together; the simulated axes do not
    couple except through the stacked masses, so this equals moving them one by one).

    Parameters
    ----------
    machine : FeedDriveMachine
    seed : int
    travel_mm : (float, float)
        Range of the +/- constant-velocity runs (steps 1-2); it must cover the processes.
    line_speed_mm_s : float
    speeds_mm_s : tuple of float
        Constant velocities of step 3 (each run in + and - direction, 2 s at speed).
    accel_speeds_mm_s, accel_mm : tuple of float, float
        Accelerated moves of step 4: forth and back over ``accel_mm`` at these speeds with the
        jerk-limited profile (peak acceleration about speed / 0.06 s), reversing at rest.
    duration_s : float

    Returns
    -------
    AirMoves
    """
    key = {
        "machine": _machine_key(machine),
        "seed": seed,
        "travel": travel_mm,
        "line": line_speed_mm_s,
        "speeds": list(speeds_mm_s),
        "accel": list(accel_speeds_mm_s),
        "accel_mm": accel_mm,
        "duration_s": duration_s,
        "version": 3,
    }
    path = cache_path("denkena2020", "air", content_key(key), ".npz")
    kinds, speeds, refs = [], [], []
    dt = 1.0 / machine.servo_rate_hz
    n = round(duration_s * machine.servo_rate_hz)
    lo, hi = travel_mm
    line = _segment(hi - lo, line_speed_mm_s, dt)
    for sign in (1, -1):
        kinds.append("line+" if sign > 0 else "line-")
        speeds.append(sign * line_speed_mm_s)
        refs.append(_hold(n, (lo if sign > 0 else hi) + sign * line))
    mid = 0.5 * (lo + hi)
    for v in speeds_mm_s:
        s = _segment(v * 2.0, v, dt)
        for sign in (1, -1):
            kinds.append("const")
            speeds.append(sign * v)
            refs.append(_hold(n, mid - sign * 0.5 * s[-1] + sign * s))
    for v in accel_speeds_mm_s:  # forth and back, reversing at rest
        s = _segment(accel_mm, v, dt)
        kinds.append("accel")
        speeds.append(0.0)
        refs.append(_hold(n, mid - 0.5 * accel_mm + s, mid + 0.5 * accel_mm - s))
    pos = np.repeat(np.stack(refs)[:, :, None], 3, axis=2)
    if path.exists():
        with np.load(path) as d:
            rec = drives.DriveRecord(d["t_s"], d["pos"], d["vel"], d["acc"], d["cur"], d["dfl"])
    else:
        vel = np.gradient(pos, dt, axis=1)
        acc = np.gradient(vel, dt, axis=1)
        rec = drives.simulate_drives(
            pos, vel, acc, np.zeros_like(pos), machine, np.random.default_rng([seed, 11])
        )
        atomic_savez(
            path,
            t_s=rec.t_s,
            pos=rec.pos_mm,
            vel=rec.vel_mm_s,
            acc=rec.acc_mm_s2,
            cur=rec.current_a,
            dfl=rec.deflection_mm,
        )
    return AirMoves(
        np.array(kinds), np.array(speeds), rec.pos_mm, rec.vel_mm_s, rec.acc_mm_s2, rec.current_a
    )
