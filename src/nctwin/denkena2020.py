"""Denkena, Bergmann & Stoppel (2020): process forces from drive signals, LSTM vs the
model-based reconstruction.

The chapter's pipeline, kept out of the notebook:

1. :func:`design_processes` draws 181 processes over the Table 1 grid (side and groove milling in
   eight feed directions, counter-clockwise circular pockets with a plunge, -y/+z ramps), marks
   a seeded share of the heavy ones semi-stable and splits 160/21 (stratified, seeded).
2. :func:`run_processes` interpolates each process, computes its milling forces
   (:mod:`nctwin.cutting`) and runs the drives (:mod:`nctwin.drives`) in batches through joblib,
   with an atomic npz cache keyed by a hash of every parameter.
3. :func:`fit_force_model` runs the air moves and fits the paper's model in its four steps
   (:mod:`nctwin.force_model`).
4. :func:`train_lstms` trains one stacked LSTM per force component with the shared loop;
   :func:`mc_dropout` gives its uncertainty band; :func:`table2` and :func:`summary` score both.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd
import torch
from joblib import Parallel, delayed
from scipy import signal

from . import cutting, drives, paths
from . import force_model as fm
from .models import ModelConfig
from .train import TrainConfig, Trained, fit

__all__ = [
    "DIRECTIONS",
    "INPUT_NAMES",
    "MODEL_CONFIG",
    "AirMoves",
    "Process",
    "Recorded",
    "design_processes",
    "fit_force_model",
    "lstm_inputs",
    "mc_dropout",
    "run_air_moves",
    "run_processes",
    "summary",
    "table2",
    "target_forces",
    "train_lstms",
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

#: The network inputs (Sec. 2.3): X, Y, Z position, velocity, acceleration, current; spindle.
INPUT_NAMES = (
    "x_mm",
    "y_mm",
    "z_mm",
    "vx_mm_s",
    "vy_mm_s",
    "vz_mm_s",
    "ax_mm_s2",
    "ay_mm_s2",
    "az_mm_s2",
    "ix_a",
    "iy_a",
    "iz_a",
    "spindle_rpm",
    "spindle_a",
)

#: Inputs scaled to [0, 1] (strictly positive); the others to [-1, 1].
POSITIVE_INPUTS = (0, 1, 2, 12, 13)

#: The paper's network: 3 stacked LSTM layers of 20 cells, dropout, one dense output.
MODEL_CONFIG = ModelConfig(
    kind="lstm", n_inputs=len(INPUT_NAMES), n_outputs=1, hidden=20, lstm_layers=3, dropout=0.2
)

_TOOL = cutting.EndMill()


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
        Chatter-like chip-thickness modulation while cutting.
    chatter_hz, chatter_depth : float
        Its frequency and relative amplitude (0 when stable).
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
    chatter_depth: float
    test: bool


def design_processes(
    grid: dict[str, list[float]],
    *,
    seed: int,
    counts: tuple[int, int, int] = (121, 36, 24),
    test_counts: tuple[int, int, int] = (14, 4, 3),
    semi_stable_share: float = 0.3,
) -> list[Process]:
    """The experiment: processes over the Table 1 grid.

    Parameters
    ----------
    grid : dict
        ``{"ap_mm": [...], "ae_mm": [...], "vf_mm_min": [...], "n_rpm": [...]}`` (Table 1).
    seed : int
    counts : (int, int, int)
        Straight (side or groove; groove where ae = D), pocket and ramp processes
        (default 181 in all).
    test_counts : (int, int, int)
        How many of each go to the test set (default 21); the split is stratified and seeded,
        and at least one semi-stable straight process is in it.
    semi_stable_share : float
        Share of the heavy processes (ap * ae >= 12 mm²) that are semi-stable, in [0, 1].

    Returns
    -------
    list of Process
    """
    if not 0.0 <= semi_stable_share <= 1.0:
        raise ValueError(
            f"semi_stable_share = {semi_stable_share!r} is out of range: allowed [0, 1]"
        )
    for name, c, tc in (("counts", counts, test_counts),):
        if (
            len(c) != 3
            or len(tc) != 3
            or any(t > n - 1 or t < 1 for t, n in zip(tc, c, strict=True))
        ):
            raise ValueError(f"{name} = {c!r}, test_counts = {tc!r}: allowed 1 <= test < count")
    rng = np.random.default_rng([seed, 7])
    seen: set = set()
    rows = []
    for kind, count in zip(("straight", "pocket", "ramp"), counts, strict=True):
        made = 0
        while made < count:
            ae = float(rng.choice(grid["ae_mm"]))
            ap = float(rng.choice(grid["ap_mm"]))
            vf = float(rng.choice(grid["vf_mm_min"]))
            n = float(rng.choice(grid["n_rpm"]))
            if kind == "straight":
                direction = str(rng.choice(list(DIRECTIONS)))
                k = "groove" if ae >= _TOOL.diameter_mm else "side"
            elif kind == "pocket":
                direction, k = "ccw", "pocket"
            else:
                direction, k = "-y/+z", "ramp"
            key = (k, direction, ae, ap, vf, n)
            if key in seen:
                continue
            seen.add(key)
            heavy = ap * ae >= 12.0 and k in ("side", "groove")
            semi = bool(heavy and rng.random() < semi_stable_share)
            start = (
                float(rng.uniform(90, 210)),
                float(rng.uniform(90, 210)),
                float(rng.uniform(60, 140)),
            )
            rows.append(
                [
                    k,
                    direction,
                    ae,
                    ap,
                    vf,
                    n,
                    start,
                    semi,
                    float(rng.uniform(45.0, 95.0)) if semi else 0.0,
                    float(rng.uniform(0.5, 0.9)) if semi else 0.0,
                ]
            )
            made += 1
    # stratified test split; one semi-stable straight process is always among the tests
    test = np.zeros(len(rows), dtype=bool)
    offsets = np.cumsum((0, *counts))
    for g, n_test in enumerate(test_counts):
        members = np.arange(offsets[g], offsets[g + 1])
        if g == 0:
            semi = members[[rows[i][7] for i in members]]
            pick = [int(rng.choice(semi))] if len(semi) else []
            rest = np.setdiff1d(members, pick)
            pick += list(rng.choice(rest, n_test - len(pick), replace=False))
        else:
            pick = list(rng.choice(members, n_test, replace=False))
        test[pick] = True
    return [Process(i, *r, test=bool(test[i])) for i, r in enumerate(rows)]


# ----------------------------------------------------------------------------------------------
# Trajectories and forces


def _segment(
    length_mm: float, speed_mm_s: float, dt: float, t1_s: float = 0.06, t2_s: float = 0.015
):
    """Arc length (n,) of one segment travelled at ``speed_mm_s`` from rest to rest: a
    rectangular velocity pulse smoothed by two moving averages (FIR interpolation, jerk-limited).
    """
    pulse = np.full(max(round(length_mm / speed_mm_s / dt), 1), speed_mm_s)
    pulse *= length_mm / (pulse.sum() * dt)
    for tau in (t1_s, t2_s):
        k = max(round(tau / dt), 1)
        pulse = np.convolve(pulse, np.full(k, 1.0 / k))
    return np.concatenate([[0.0], np.cumsum(pulse) * dt])


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
    r = _TOOL.radius_mm
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
        flag = np.where(weight > 0, 1 if p.ae_mm >= _TOOL.diameter_mm else 2, 0)
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


def _process_signals(p: Process, n_steps: int, dt: float):
    """Set points (pos, vel, acc), force on the workpiece (n, 3), torque (n,), rpm (n,)."""
    pos, angle, weight, depth, flag = _trajectory(p, n_steps, dt)
    vel = np.gradient(pos, dt, axis=0)
    acc = np.gradient(vel, dt, axis=0)
    t = np.arange(n_steps) * dt
    tooth_hz = _TOOL.teeth * p.n_rpm / 60.0
    fz = np.linalg.norm(vel[:, :2], axis=1) / tooth_hz
    if p.semi_stable:
        env = 0.5 * (1 + np.sin(2 * np.pi * 0.7 * t + p.index))
        mod = p.chatter_depth * env * np.sin(2 * np.pi * p.chatter_hz * t)
    else:
        mod = 0.0
    force = np.zeros((n_steps, 3))
    torque = np.zeros(n_steps)
    for code, ae in ((1, _TOOL.diameter_mm), (2, p.ae_mm)):
        on = flag == code
        if not on.any():
            continue
        mode = "down"
        st, ex = cutting.immersion(min(ae, _TOOL.diameter_mm), _TOOL.radius_mm, mode)
        f, tq = cutting.tool_forces(
            t[on],
            spindle_rpm=p.n_rpm,
            feed_per_tooth_mm=fz[on],
            ap_mm=depth[on],
            phi_start_rad=st,
            phi_exit_rad=ex,
            tool=_TOOL,
            modulation=np.broadcast_to(mod, t.shape)[on],
        )
        force[on] = cutting.workpiece_forces(f * weight[on, None], angle[on])
        torque[on] = tq * weight[on]
    plunge = flag == 3
    ax_f, ax_t = cutting.plunge_forces(np.clip(-vel[plunge, 2], 0, None) / tooth_hz, tool=_TOOL)
    force[plunge, 2] = -ax_f * weight[plunge]
    torque[plunge] = ax_t * weight[plunge]
    return pos, vel, acc, force, torque, np.full(n_steps, p.n_rpm)


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


def _cache_path(kind: str, key: dict):
    digest = hashlib.sha256(json.dumps(key, sort_keys=True, default=str).encode()).hexdigest()
    return paths.cache_dir() / "denkena2020" / f"{kind}-{digest[:16]}.npz"


def _atomic_savez(path, **arrays) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".npz")
    os.close(fd)
    try:
        np.savez(tmp, **arrays)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


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
        "version": 1,
    }
    path = _cache_path("processes", key)
    if path.exists():
        with np.load(path) as d:
            return Recorded(processes, d["t_s"], d["inputs"], d["force_n"], float(d["seconds"]))
    import time

    t0 = time.perf_counter()
    batches = [processes[i : i + batch_size] for i in range(0, len(processes), batch_size)]
    out = Parallel(n_jobs=n_jobs)(delayed(_batch)(b, machine, duration_s, seed) for b in batches)
    t_s = out[0][0]
    inputs = np.concatenate([o[1] for o in out])
    force = np.concatenate([o[2] for o in out])
    seconds = time.perf_counter() - t0
    _atomic_savez(path, t_s=t_s, inputs=inputs, force_n=force, seconds=seconds)
    return Recorded(processes, t_s, inputs, force, seconds)


# ----------------------------------------------------------------------------------------------
# Air moves and the model-based reconstruction


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
        "version": 1,
    }
    path = _cache_path("air", key)
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
            rec = drives.DriveRecord(d["t_s"], d["pos"], d["vel"], d["acc"], d["cur"])
    else:
        vel = np.gradient(pos, dt, axis=1)
        acc = np.gradient(vel, dt, axis=1)
        rec = drives.simulate_drives(
            pos, vel, acc, np.zeros_like(pos), machine, np.random.default_rng([seed, 11])
        )
        _atomic_savez(
            path,
            t_s=rec.t_s,
            pos=rec.pos_mm,
            vel=rec.vel_mm_s,
            acc=rec.acc_mm_s2,
            cur=rec.current_a,
        )
    return AirMoves(
        np.array(kinds), np.array(speeds), rec.pos_mm, rec.vel_mm_s, rec.acc_mm_s2, rec.current_a
    )


def fit_force_model(air: AirMoves, km_n_a: np.ndarray) -> tuple[fm.ForceModel, pd.DataFrame]:
    """Fit the paper's model in its four steps (Sec. 2.2).

    Parameters
    ----------
    air : AirMoves
    km_n_a : ndarray, shape (3,)
        Motor constants (data sheet).

    Returns
    -------
    ForceModel
    pandas.DataFrame
        The step-3 points (axis, velocity, :math:`\\tilde F_{fr}`) for Fig. 2.
    """
    axes, points, f_m, a_m = [], [], [], []
    for i in range(3):
        motor = km_n_a[i] * air.current_a[:, :, i]
        runs = {}
        for sign, kind in ((1, "line+"), (-1, "line-")):
            b = int(np.flatnonzero(air.kind == kind)[0])
            steady = np.abs(air.vel_mm_s[b, :, i] - air.speed_mm_s[b]) < 0.05 * abs(
                air.speed_mm_s[b]
            )
            runs[sign] = (air.pos_mm[b, steady, i], motor[b, steady])
        k, s_r, grid, table = fm.fit_restoring(*runs[1], *runs[-1])
        partial = fm.AxisModel(
            km_n_a[i], k, s_r, grid, table, fm.StribeckParams(0.0, 0.0, 1.0, 0.0)
        )
        vs, ffr = [], []
        for b in np.flatnonzero(air.kind == "const"):
            v = air.speed_mm_s[b]
            steady = np.abs(air.vel_mm_s[b, :, i] - v) < max(0.1 * abs(v), 0.05)
            if steady.sum() < 5:
                continue
            resid = motor[b, steady] - partial.position_force_n(air.pos_mm[b, steady, i])
            vs.append(v)
            ffr.append(float(resid.mean()))
        friction = fm.fit_stribeck(np.array(vs), np.array(ffr))
        axes.append(fm.AxisModel(km_n_a[i], k, s_r, grid, table, friction))
        points += [
            {"axis": "XYZ"[i], "v_mm_s": v, "friction_n": f} for v, f in zip(vs, ffr, strict=True)
        ]
        acc_runs = np.flatnonzero(air.kind == "accel")
        s = air.pos_mm[acc_runs, :, i].ravel()
        v = air.vel_mm_s[acc_runs, :, i].ravel()
        f_m.append(
            motor[acc_runs].ravel() - axes[i].position_force_n(s) - fm.stribeck_n(v, friction)
        )
        a_m.append(air.acc_mm_s2[acc_runs, :, i].ravel())
    masses = fm.fit_masses(f_m, a_m)
    return fm.ForceModel(tuple(axes), masses), pd.DataFrame(points)


def reconstruct(model: fm.ForceModel, inputs: np.ndarray) -> np.ndarray:
    """Model-based forces (R, 3) from one process' recorded inputs (R, 14)."""
    return model.reconstruct(inputs[:, 0:3], inputs[:, 3:6], inputs[:, 6:9], inputs[:, 9:12])


# ----------------------------------------------------------------------------------------------
# The LSTM


def target_forces(force_n: np.ndarray, record_rate_hz: float, cutoff_hz: float = 120.0):
    """Zero-phase Butterworth low-pass of the measured forces (Sec. 2.3), shape kept."""
    b, a = signal.butter(2, cutoff_hz, fs=record_rate_hz)
    return signal.filtfilt(b, a, force_n, axis=-2)


@dataclass(frozen=True)
class InputScaling:
    """The paper's scalings, fitted on the training processes: inputs to [-1, 1] (x / max|x|)
    or, for :data:`POSITIVE_INPUTS`, to [0, 1] (min-max); forces by eq. 17,
    :math:`F^* = F / (2 |F_{max}|) + 0.5`.

    Parameters
    ----------
    offset, scale : ndarray, shape (14,)
    force_max_n : ndarray, shape (3,)
    """

    offset: np.ndarray
    scale: np.ndarray
    force_max_n: np.ndarray

    @classmethod
    def fit(cls, inputs: np.ndarray, forces: np.ndarray) -> InputScaling:
        """From training inputs (P, R, 14) and filtered forces (P, R, 3)."""
        x = inputs.reshape(-1, inputs.shape[-1])
        offset = np.zeros(x.shape[1])
        scale = np.abs(x).max(axis=0)
        pos = list(POSITIVE_INPUTS)
        offset[pos] = x[:, pos].min(axis=0)
        scale[pos] = x[:, pos].max(axis=0) - offset[pos]
        scale = np.where(scale > 0, scale, 1.0)
        return cls(offset, scale, np.abs(forces.reshape(-1, 3)).max(axis=0))

    def inputs(self, x: np.ndarray) -> np.ndarray:
        return (x - self.offset) / self.scale

    def force(self, f: np.ndarray, axis: int) -> np.ndarray:
        """Eq. 17."""
        return f / (2.0 * self.force_max_n[axis]) + 0.5

    def force_inverse(self, f_star: np.ndarray, axis: int) -> np.ndarray:
        return (f_star - 0.5) * 2.0 * self.force_max_n[axis]


def train_lstms(
    recorded: Recorded, targets: np.ndarray, train_config: TrainConfig, *, progress: bool = True
) -> tuple[dict[str, Trained], InputScaling]:
    """One network per force component on the training processes (:func:`nctwin.train.fit`).

    Parameters
    ----------
    recorded : Recorded
    targets : ndarray, shape (P, R, 3)
        Filtered forces (:func:`target_forces`).
    train_config : TrainConfig
    progress : bool

    Returns
    -------
    dict
        ``{"X": Trained, "Y": ..., "Z": ...}``.
    InputScaling
    """
    train = np.array([not p.test for p in recorded.processes])
    scaling = InputScaling.fit(recorded.inputs[train], targets[train])
    xs = [scaling.inputs(x) for x in recorded.inputs[train]]
    nets = {}
    for i, axis in enumerate("XYZ"):
        ys = [scaling.force(y[:, [i]], i) for y in targets[train]]
        nets[axis] = fit(
            MODEL_CONFIG,
            train_config,
            xs,
            ys,
            name=f"denkena2020_{axis.lower()}",
            progress=progress,
        )
    return nets, scaling


def lstm_inputs(scaling: InputScaling, inputs: np.ndarray) -> np.ndarray:
    """Scaled network inputs (R, 14) of one process."""
    return scaling.inputs(inputs)


def predict(nets: dict[str, Trained], scaling: InputScaling, inputs: np.ndarray) -> np.ndarray:
    """LSTM forces (R, 3) of one process."""
    x = scaling.inputs(inputs)
    return np.stack(
        [scaling.force_inverse(nets[a].predict(x)[:, 0], i) for i, a in enumerate("XYZ")], axis=1
    )


def mc_dropout(
    nets: dict[str, Trained],
    scaling: InputScaling,
    inputs: np.ndarray,
    *,
    samples: int,
    seed: int,
    axes: str = "XY",
) -> np.ndarray:
    """Monte-Carlo dropout: forces (samples, R, len(axes)) with dropout left on at prediction.

    The dropout masks come from a forked, seeded torch generator (no global state changes).
    """
    x = scaling.inputs(inputs)
    out = np.empty((samples, len(x), len(axes)))
    for j, a in enumerate(axes):
        i = "XYZ".index(a)
        model = nets[a].model
        model.train()
        try:
            with torch.random.fork_rng(devices=[]):
                torch.manual_seed(seed)
                for k in range(samples):
                    out[k, :, j] = scaling.force_inverse(nets[a].predict(x)[:, 0], i)
        finally:
            model.eval()
    return out


# ----------------------------------------------------------------------------------------------
# Scores


def _rmse(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean((a - b) ** 2)))


def table2(
    recorded: Recorded,
    targets: np.ndarray,
    lstm: dict[int, np.ndarray],
    model: dict[int, np.ndarray],
    axes: str = "XY",
) -> pd.DataFrame:
    """RMSE of the LSTM and the model per test process and axis, with max |F_meas|.

    Parameters
    ----------
    recorded : Recorded
    targets : ndarray, shape (P, R, 3)
        Filtered measured forces (the paper's reference).
    lstm, model : dict
        Process index -> forces (R, 3).
    axes : str
        Axes reported (paper: X and Y).
    """
    rows = []
    for p in recorded.processes:
        if not p.test:
            continue
        for axis in axes:
            i = "XYZ".index(axis)
            f = targets[p.index, :, i]
            rows.append(
                {
                    "process": {
                        "side": "side milling",
                        "groove": "groove milling",
                        "pocket": "circular pocket",
                        "ramp": "ramp milling",
                    }[p.kind],
                    "feed_direction": p.feed_direction,
                    "ae_mm": p.ae_mm,
                    "ap_mm": p.ap_mm,
                    "vf_mm_min": p.vf_mm_min,
                    "n_rpm": p.n_rpm,
                    "axis": axis,
                    "lstm_rmse_n": _rmse(lstm[p.index][:, i], f),
                    "model_rmse_n": _rmse(model[p.index][:, i], f),
                    "max_abs_force_n": float(np.abs(f).max()),
                    "semi_stable": p.semi_stable,
                }
            )
    return pd.DataFrame(rows)


def summary(table: pd.DataFrame, paper: pd.DataFrame) -> pd.DataFrame:
    """Mean LSTM and model RMSE, % lower, median LSTM RMSE; beside the paper's numbers
    (``paper``: the ``denkena2020_summary`` table)."""
    q = paper.set_index("quantity")["value"]
    mean_l, mean_m = table["lstm_rmse_n"].mean(), table["model_rmse_n"].mean()
    return pd.DataFrame(
        [
            {
                "mean_lstm_rmse_n": mean_l,
                "mean_model_rmse_n": mean_m,
                "lstm_lower_pct": 100.0 * (1.0 - mean_l / mean_m),
                "median_lstm_rmse_n": table["lstm_rmse_n"].median(),
                "paper_mean_lstm_rmse_n": q["lstm_rmse_mean"],
                # implied by the two printed numbers (mean LSTM RMSE, % lower)
                "paper_mean_model_rmse_n": q["lstm_rmse_mean"]
                / (1.0 - q["lstm_rmse_lower_than_model"] / 100.0),
                "paper_lstm_lower_pct": q["lstm_rmse_lower_than_model"],
                "paper_median_lstm_rmse_n": q["lstm_rmse_median"],
            }
        ]
    )
