"""Record the shipped LinuxCNC recordings: ``make record`` (``python -m nctwin.record``).

LinuxCNC (:mod:`nctwin.kernel.linuxcnc`) is the measured machine. This module runs it on paper
1's training programs (:func:`nctwin.programs.training.training_specs`, F 65-100 mm/s,
G64 P 0.05-0.5 mm), a broader set (:data:`BROAD`), CAM-style programs
(:func:`nctwin.programs.camstyle.cam_program`), the test programs (toolpaths I and II, the
pocket; F 75 and 92 mm/s, G64 P 0.3 and 0.4 mm), programs in the whole language
(:data:`nctwin.programs.language.LANGUAGE_PROGRAMS`: cycles, cutter compensation, subroutines,
parameters) and the public programs of
:func:`nctwin.paths.public_programs_dir`, and saves them in the format of
:mod:`nctwin.recordings`, which loads them without LinuxCNC.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .cache import atomic_write_text
from .estimate.cam import cam as estimate_cam
from .gcode import GCodeError, parse
from .kernel import linuxcnc
from .machine import Profile, load_profile
from .paths import linuxcnc_samples_dir, public_programs_dir
from .programs.camstyle import cam_program
from .programs.language import LANGUAGE_PROGRAMS
from .programs.pocket import pocket_program
from .programs.training import broad_program, contour_program, training_specs
from .recordings import (
    MACHINE,
    TRACE_PERIOD_S,
    RecordedProgram,
    recording_dir,
    rejected_file,
    text_sha256,
    trace_sha256,
)
from .runner import run_tasks
from .targets import block_targets

__all__ = [
    "PUBLIC_SUFFIXES",
    "RECORDED_SETS",
    "record_program",
    "record_public",
    "record_set",
    "recording_programs",
]


#: The shipped set: seed and size of :func:`~nctwin.programs.training.training_specs`.
RECORD_SEED = 9


N_PROGRAMS = 60


N_LINES = 200


FEED_RANGE_MM_S = (65.0, 100.0)


TOL_RANGE_MM = (0.05, 0.5)


#: The broad set (:func:`~nctwin.programs.training.broad_program`): seed, size and ranges that
#: cover what other people's programs ask of the machine (slow and fast feeds, tight and no
#: tolerances, 3D lines).
BROAD_SEED = 10


N_BROAD = 100


BROAD = dict(
    n_lines=400,
    feed_range_mm_s=(5.0, 200.0),
    tol_range_mm=(0.01, 1.0),
    no_tol_share=0.2,
    naive_share=0.3,
    global_length_mm=(0.01, 1.0),
    max_tilt_rad=math.pi / 3,
    max_time_s=60.0,
)


#: The CAM-style set (:func:`~nctwin.programs.camstyle.cam_program`): seed and size. Operations
#: joined by rapids, engraving chords, 3D rasters, reversals, every path-control mode.
CAM_SEED = 11


N_CAM = 60


#: Runs again after LinuxCNC aborted a program (busy machine), at half the speed-up after the
#: first.
RETRIES = 3


#: Feeds and tolerances of the test programs (those of the Chien chapter's test set).
TEST_FEEDS_MM_S = (75.0, 92.0)


TEST_TOLS_MM = (0.3, 0.4)


#: The sets of :func:`recording_programs`.
RECORDED_SETS = ("train", "broad", "cam", "test", "language")


def recording_programs(sets: tuple[str, ...] = RECORDED_SETS) -> dict[str, str]:
    """The shipped set: name -> G-code text (see the module docstring).

    ``train_*``: paper 1's training programs (:data:`N_PROGRAMS` of :data:`N_LINES` lines);
    ``broad_*``: the broad set (:data:`BROAD`); ``cam_*``: the CAM-style set (:data:`N_CAM`
    programs); ``test_*``: toolpaths I and II and the pocket; ``lang_*``: the programs of
    :data:`~nctwin.programs.language.LANGUAGE_PROGRAMS`. ``sets`` picks some of them.
    """
    unknown = set(sets) - set(RECORDED_SETS)
    if unknown:
        raise ValueError(f"sets = {sets!r} is not allowed: allowed {', '.join(RECORDED_SETS)}")
    out: dict[str, str] = {}
    specs = training_specs(
        RECORD_SEED,
        n_programs=N_PROGRAMS,
        n_lines=N_LINES,
        feed_range_mm_s=FEED_RANGE_MM_S,
        tol_range_mm=TOL_RANGE_MM,
    )
    if "train" in sets:
        out |= {f"train_{i:02d}_{s.family}": _q0(s.text(), s.tol_mm) for i, s in enumerate(specs)}
    if "broad" in sets:
        rng = np.random.default_rng(BROAD_SEED)
        out |= {f"broad_{i:03d}": broad_program(rng, **BROAD) for i in range(N_BROAD)}
    if "cam" in sets:
        rng = np.random.default_rng(CAM_SEED)
        out |= {f"cam_{i:03d}": cam_program(rng) for i in range(N_CAM)}
    for name in ("I", "II", "pocket") if "test" in sets else ():
        for f in TEST_FEEDS_MM_S:
            for e in TEST_TOLS_MM:
                text = (
                    pocket_program(feed_mm_s=f, tol_mm=e)
                    if name == "pocket"
                    else contour_program(name, feed_mm_s=f, tol_mm=e)
                )
                out[f"test_{name}_F{f:g}_P{e:g}"] = _q0(text, e)
    if "language" in sets:
        out |= {f"lang_{name}": program() for name, program in LANGUAGE_PROGRAMS.items()}
    return out


def _q0(text: str, tol_mm: float) -> str:
    """The program with ``G64 P<tol>`` written as ``G64 P<tol> Q0``.

    On LinuxCNC a ``G64 P`` without Q sets Q = P, which merges nearly collinear short lines
    into one (its naive-CAM detector) and so changes the path itself. The recorded set keeps the
    programmed path and measures blending alone, as paper 1's training programs mean it.
    """
    old, new = f"\nG64 P{tol_mm:g}\n", f"\nG64 P{tol_mm:g} Q0\n"
    if text.count(old) != 1:
        raise ValueError(f"expected one line 'G64 P{tol_mm:g}' in the program")
    return text.replace(old, new)


def record_program(
    name: str,
    program: str,
    profile: Profile,
    *,
    speed: float = 5,
    source: str = "nctwin",
    timeout_s: float = 600.0,
) -> RecordedProgram:
    """Record one program on LinuxCNC and reduce it to what is shipped.

    ``source`` other than ``nctwin`` marks a public program: its text is not kept. A run that
    LinuxCNC aborts (a busy machine) is repeated up to :data:`RETRIES` times.
    Raises what :func:`nctwin.kernel.linuxcnc.run` raises.
    """
    tp = parse(program, tool_table=profile.tool_table)
    for attempt in range(RETRIES + 1):
        try:
            motion = linuxcnc.run(
                program,
                profile.machine,
                profile.control("planner"),
                speed=speed,
                timeout_s=timeout_s,
                tool_table=profile.tool_table,
            )
            break
        except linuxcnc.LinuxCNCAborted:
            if attempt == RETRIES:
                raise
            # a busy machine: try again, then more slowly (the trace does not change)
            speed = max(1.0, speed / 2) if attempt else speed
    step = round(TRACE_PERIOD_S / motion.period_s)
    return RecordedProgram(
        name=name,
        program=program if source == "nctwin" else "",
        program_sha256=text_sha256(program),
        source=source,
        machine=profile.name,
        targets=block_targets(motion, tp),
        feed_mm_s=motion.speed_mm_s[::step].astype(np.float32),
        n_samples=len(motion),
        trace_sha256=trace_sha256(motion),
    )


def record_set(
    folder: Path | None = None,
    *,
    n_jobs: int = 2,
    speed: float = 5,
    sets: tuple[str, ...] = RECORDED_SETS,
) -> list[RecordedProgram]:
    """Record every program of :func:`recording_programs` and save them into ``folder``.

    Parameters
    ----------
    folder : Path, optional
        Default :func:`recording_dir`.
    n_jobs : int
        LinuxCNC instances at a time (threads of :func:`nctwin.runner.run_tasks`: each instance
        is its own process).
    speed : float
        Speed-up over real time (see :func:`nctwin.kernel.linuxcnc.record`).
    sets : tuple of str
        Which programs (see :func:`recording_programs`).
    """
    folder = recording_dir() if folder is None else Path(folder)
    profile = load_profile(MACHINE)
    programs = recording_programs(sets)
    tasks = ((n, t, profile, speed) for n, t in programs.items())
    out = run_tasks(_record_one, tasks, n_jobs=n_jobs, threads=True, desc="LinuxCNC")
    for rec in out:
        rec.save(folder)
    return out


def _record_one(name: str, program: str, profile: Profile, speed: float) -> RecordedProgram:
    return record_program(name, program, profile, speed=speed)


#: Suffixes of the public programs that are recorded.
PUBLIC_SUFFIXES = (".ngc", ".nc", ".gcode")


def _record_public_one(
    path: Path, profile: Profile, speed: float, prefix: str
) -> RecordedProgram | tuple[str, str]:
    text = path.read_text(encoding="utf-8", errors="replace")
    try:
        tp = parse(text, source=path.name, tool_table=profile.tool_table)
        cam_s = estimate_cam(tp, profile.machine).cycle_time_s
        # generous: LinuxCNC takes up to several times the CAM time on short segments
        timeout_s = 120.0 + 20.0 * cam_s / speed
        return record_program(
            f"{prefix}{path.stem}",
            text,
            profile,
            speed=speed,
            source=f"public/{path.relative_to(public_programs_dir()).as_posix()}",
            timeout_s=timeout_s,
        )
    # LinuxCNCError is a GCodeError
    except (GCodeError, TimeoutError, linuxcnc.LinuxCNCAborted) as exc:
        return path.name, str(exc)


def record_public(
    folder: Path | None = None,
    out: Path | None = None,
    *,
    n_jobs: int = 2,
    speed: float = 5,
    prefix: str = "public_",
) -> tuple[list[RecordedProgram], dict[str, str]]:
    """Record every public program in ``folder`` that nctwin and LinuxCNC accept.

    Parameters
    ----------
    folder : Path, optional
        Default :func:`nctwin.paths.public_programs_dir`; a folder inside it (such as
        :func:`nctwin.paths.linuxcnc_samples_dir`) for a set of its own.
    out : Path, optional
        Where to save them; default :func:`recording_dir`.
    n_jobs, speed
        See :func:`record_set`.
    prefix : str
        The recordings' names: ``prefix`` and the file's stem (``public_``, or ``sample_`` for
        LinuxCNC's samples).

    Returns
    -------
    recorded : list of RecordedProgram
    rejected : dict
        File name -> the reason nctwin or LinuxCNC gave; also written to
        ``<out>/<prefix>rejected.json``.
    """
    folder = public_programs_dir() if folder is None else Path(folder)
    out = recording_dir() if out is None else Path(out)
    if not folder.is_dir():
        raise ValueError(f"{folder} is not a folder of public programs")
    profile = load_profile(MACHINE)
    paths = sorted(p for p in folder.iterdir() if p.suffix in PUBLIC_SUFFIXES)
    tasks = ((p, profile, speed, prefix) for p in paths)
    recorded, rejected = [], {}
    for res in run_tasks(
        _record_public_one, tasks, n_jobs=n_jobs, threads=True, desc="LinuxCNC public"
    ):
        if isinstance(res, RecordedProgram):
            res.save(out)
            recorded.append(res)
        else:
            rejected[res[0]] = res[1]
    text = json.dumps(rejected, indent=1, sort_keys=True) + "\n"
    atomic_write_text(out / rejected_file(prefix), text)
    return recorded, rejected


def main() -> None:
    """``make record``: re-record the shipped set (and the public programs, where they lie
    beside the clone) and print one line per program."""
    recorded = record_set()
    if public_programs_dir().is_dir():
        for folder, prefix in ((None, "public_"), (linuxcnc_samples_dir(), "sample_")):
            public, rejected = record_public(folder, prefix=prefix)
            recorded += public
            for name, reason in rejected.items():
                print(f"record: {name}: rejected: {reason}")
    else:
        print(f"record: {public_programs_dir()} is absent: public programs not re-recorded")
    for rec in recorded:
        print(
            f"record: {rec.name}: {len(rec.targets.time_s)} blocks, "
            f"{rec.cycle_time_s:.3f} s, sha256 {rec.trace_sha256[:12]}"
        )
    print(f"record: {recording_dir()}")


if __name__ == "__main__":
    main()
