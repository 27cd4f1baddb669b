"""Shipped recordings of a real NC kernel (LinuxCNC): record them, save them, load them.

LinuxCNC (:mod:`nctwin.kernel.linuxcnc`) is the measured machine. Its recordings of paper 1's
training programs (:func:`nctwin.programs.training.training_specs`, F 65-100 mm/s,
G64 P 0.05-0.5 mm), of a broader set (:data:`BROAD`), of CAM-style programs
(:func:`nctwin.programs.camstyle.cam_program`) and of the test programs (toolpaths I and II, the
pocket; F 75 and 92 mm/s, G64 P 0.3 and 0.4 mm) are shipped as a measurement, the way a
paper's data set would be, so that chapters use them without LinuxCNC. ``make record``
re-records them from nothing (it needs ``make linuxcnc``); :func:`load_recordings` reads them.

Public part programs written by others (``../shared/programs/``, GPL) are recorded the same way
(:func:`record_public`) and shipped as measurements only, without their text: a chapter that
uses them reads the text from where it lies and checks it against ``program_sha256``
(:func:`public_program_text`).

One compressed file per program, ``data/recordings/linuxcnc/<name>.npz``, with

* ``program``: the G-code text that was run (empty for a public program, which is not ours to
  ship), ``program_sha256``: the SHA-256 of that text, ``source``: where it comes from
  (``nctwin`` or ``public/<file name>``), ``machine``: the profile's name;
* ``junction_sample``, ``length_mm``, ``time_s``: the per-block targets
  (:func:`nctwin.features.block_targets`, Chien et al. 2023, eq. 1-3);
* ``feed_mm_s``: the path speed every :data:`TRACE_PERIOD_S` (every ``k``-th servo sample,
  for figures);
* ``n_samples`` and ``trace_sha256``: the length and the SHA-256 of the full recorded position
  trace (float64, shape (n, 3)), so a live run can be checked against the shipped one bit for bit.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from joblib import Parallel, delayed
from tqdm import tqdm

from .estimate.cam import cam as estimate_cam
from .features import BlockTargets, block_targets
from .gcode import GCodeError, parse
from .kernel.linuxcnc import LinuxCNCAborted
from .machine import MachineProfile, load_machine
from .motion import Motion
from .paths import atomic_write_text, data_dir, public_programs_dir
from .programs.camstyle import cam_program
from .programs.pocket import pocket_program
from .programs.training import broad_program, contour_program, training_specs

__all__ = [
    "MACHINE",
    "TRACE_PERIOD_S",
    "RecordedProgram",
    "load_recordings",
    "public_program_text",
    "record_program",
    "record_public",
    "record_set",
    "recording_dir",
    "recording_programs",
    "text_sha256",
    "trace_sha256",
]

#: Profile of the shipped recordings.
MACHINE = "linuxcnc_sim"
#: Period of the shipped feed trace (s).
TRACE_PERIOD_S = 0.01
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


@dataclass(frozen=True, eq=False)
class RecordedProgram:
    """One program recorded on LinuxCNC, as shipped.

    Parameters
    ----------
    name : str
        File stem, e.g. ``train_00_mixed`` or ``test_II_F92_P0.3``.
    program : str
        G-code text that was run.
    machine : str
        Profile name.
    targets : BlockTargets
        Per-block junction samples, blended lengths and times.
    feed_mm_s : ndarray, shape (m,)
        Path speed every :data:`TRACE_PERIOD_S`.
    n_samples : int
        Samples of the full trace (servo periods + 1).
    trace_sha256 : str
        SHA-256 of the full position trace (see :func:`trace_sha256`).
    program_sha256 : str
        SHA-256 of the program text (UTF-8).
    source : str
        ``nctwin`` for the package's own programs (text shipped), ``public/<file name>`` for a
        public program (text not shipped, ``program`` is empty).
    """

    name: str
    program: str
    machine: str
    targets: BlockTargets
    feed_mm_s: np.ndarray
    n_samples: int
    trace_sha256: str
    program_sha256: str
    source: str = "nctwin"

    @property
    def cycle_time_s(self) -> float:
        """Measured cycle time (eq. 3)."""
        return self.targets.cycle_time_s

    def save(self, folder: Path) -> Path:
        """Write ``<folder>/<name>.npz`` atomically (temporary file, then rename)."""
        folder.mkdir(parents=True, exist_ok=True)
        buf = io.BytesIO()
        np.savez_compressed(
            buf,
            program=np.array(self.program),
            machine=np.array(self.machine),
            junction_sample=self.targets.junction_sample,
            length_mm=self.targets.length_mm,
            time_s=self.targets.time_s,
            feed_mm_s=self.feed_mm_s,
            n_samples=np.array(self.n_samples),
            trace_sha256=np.array(self.trace_sha256),
            program_sha256=np.array(self.program_sha256),
            source=np.array(self.source),
        )
        path = folder / f"{self.name}.npz"
        tmp = path.with_name(f".{path.name}.tmp")
        tmp.write_bytes(buf.getvalue())
        tmp.replace(path)
        return path

    @classmethod
    def load(cls, path: Path) -> RecordedProgram:
        """Read one shipped recording."""
        with np.load(path) as d:
            return cls(
                name=Path(path).stem,
                program=str(d["program"]),
                machine=str(d["machine"]),
                targets=BlockTargets(d["junction_sample"], d["length_mm"], d["time_s"]),
                feed_mm_s=d["feed_mm_s"],
                n_samples=int(d["n_samples"]),
                trace_sha256=str(d["trace_sha256"]),
                program_sha256=str(d["program_sha256"]),
                source=str(d["source"]),
            )


def recording_dir() -> Path:
    """Folder of the shipped LinuxCNC recordings."""
    return data_dir() / "recordings" / "linuxcnc"


def recording_programs(
    sets: tuple[str, ...] = ("train", "broad", "cam", "test"),
) -> dict[str, str]:
    """The shipped set: name -> G-code text (see the module docstring).

    ``train_*``: paper 1's training programs (:data:`N_PROGRAMS` of :data:`N_LINES` lines);
    ``broad_*``: the broad set (:data:`BROAD`); ``cam_*``: the CAM-style set (:data:`N_CAM`
    programs); ``test_*``: toolpaths I and II and the pocket. ``sets`` picks some of them.
    """
    unknown = set(sets) - {"train", "broad", "cam", "test"}
    if unknown:
        raise ValueError(f"sets = {sets!r} is not allowed: allowed train, broad, cam, test")
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


def trace_sha256(motion: Motion) -> str:
    """SHA-256 of a motion's positions (float64, C order): equal hashes, equal traces."""
    pos = np.ascontiguousarray(motion.pos_mm, dtype=np.float64)
    return hashlib.sha256(pos.tobytes()).hexdigest()


def text_sha256(text: str) -> str:
    """SHA-256 of a program text (UTF-8)."""
    return hashlib.sha256(text.encode()).hexdigest()


def record_program(
    name: str,
    program: str,
    machine: MachineProfile,
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
    from .kernel import linuxcnc

    tp = parse(program)
    for attempt in range(RETRIES + 1):
        try:
            motion = linuxcnc.run(program, machine, speed=speed, timeout_s=timeout_s)
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
        machine=machine.name,
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
    sets: tuple[str, ...] = ("train", "broad", "cam", "test"),
) -> list[RecordedProgram]:
    """Record every program of :func:`recording_programs` and save them into ``folder``.

    Parameters
    ----------
    folder : Path, optional
        Default :func:`recording_dir`.
    n_jobs : int
        LinuxCNC instances at a time (joblib, threads: each instance is its own process).
    speed : float
        Speed-up over real time (see :func:`nctwin.kernel.linuxcnc.record`).
    sets : tuple of str
        Which programs (see :func:`recording_programs`).
    """
    if not isinstance(n_jobs, int) or n_jobs < 1:
        raise ValueError(f"n_jobs = {n_jobs!r} is out of range: allowed integers >= 1")
    folder = recording_dir() if folder is None else Path(folder)
    machine = load_machine(MACHINE)
    programs = recording_programs(sets)
    jobs = (delayed(record_program)(n, t, machine, speed=speed) for n, t in programs.items())
    parallel = Parallel(n_jobs=n_jobs, backend="threading", return_as="generator")
    out = []
    for rec in tqdm(parallel(jobs), total=len(programs), desc="LinuxCNC", mininterval=5.0):
        rec.save(folder)
        out.append(rec)
    return out


#: Suffixes of the public programs that are recorded.
PUBLIC_SUFFIXES = (".ngc", ".nc", ".gcode")
#: File listing the public programs nctwin or LinuxCNC rejects, with the reason.
PUBLIC_REJECTED = "public_rejected.json"


def public_program_text(rec: RecordedProgram, folder: Path | None = None) -> str | None:
    """The text of a recorded public program, read from ``folder`` (default
    :func:`nctwin.paths.public_programs_dir`); None where the file is absent.

    Raises
    ------
    ValueError
        If the file is there but is not the text that was recorded (SHA-256 differs).
    """
    if rec.source == "nctwin":
        return rec.program
    folder = public_programs_dir() if folder is None else Path(folder)
    path = folder / rec.source.removeprefix("public/")
    if not path.is_file():
        return None
    text = path.read_text(encoding="utf-8", errors="replace")
    if text_sha256(text) != rec.program_sha256:
        raise ValueError(
            f"{path} is not the program recorded as {rec.name} (SHA-256 differs): "
            "re-record the public programs with `make record`"
        )
    return text


def _record_public_one(
    path: Path, machine: MachineProfile, speed: float
) -> RecordedProgram | tuple[str, str]:
    text = path.read_text(encoding="utf-8", errors="replace")
    try:
        tp = parse(text, source=path.name)
        cam_s = estimate_cam(tp, machine).cycle_time_s
        # generous: LinuxCNC takes up to several times the CAM time on short segments
        timeout_s = 120.0 + 20.0 * cam_s / speed
        return record_program(
            f"public_{path.stem}",
            text,
            machine,
            speed=speed,
            source=f"public/{path.name}",
            timeout_s=timeout_s,
        )
    except (GCodeError, TimeoutError, LinuxCNCAborted) as exc:  # LinuxCNCError: a GCodeError
        return path.name, str(exc)


def record_public(
    folder: Path | None = None,
    out: Path | None = None,
    *,
    n_jobs: int = 2,
    speed: float = 5,
) -> tuple[list[RecordedProgram], dict[str, str]]:
    """Record every public program in ``folder`` that nctwin and LinuxCNC accept.

    Parameters
    ----------
    folder : Path, optional
        Default :func:`nctwin.paths.public_programs_dir`.
    out : Path, optional
        Where to save them; default :func:`recording_dir`.
    n_jobs, speed
        See :func:`record_set`.

    Returns
    -------
    recorded : list of RecordedProgram
    rejected : dict
        File name -> the reason nctwin or LinuxCNC gave; also written to
        ``<out>/public_rejected.json``.
    """
    if not isinstance(n_jobs, int) or n_jobs < 1:
        raise ValueError(f"n_jobs = {n_jobs!r} is out of range: allowed integers >= 1")
    folder = public_programs_dir() if folder is None else Path(folder)
    out = recording_dir() if out is None else Path(out)
    if not folder.is_dir():
        raise ValueError(f"{folder} is not a folder of public programs")
    machine = load_machine(MACHINE)
    paths = sorted(p for p in folder.iterdir() if p.suffix in PUBLIC_SUFFIXES)
    jobs = (delayed(_record_public_one)(p, machine, speed) for p in paths)
    parallel = Parallel(n_jobs=n_jobs, backend="threading", return_as="generator")
    recorded, rejected = [], {}
    for res in tqdm(parallel(jobs), total=len(paths), desc="LinuxCNC public", mininterval=5.0):
        if isinstance(res, RecordedProgram):
            res.save(out)
            recorded.append(res)
        else:
            rejected[res[0]] = res[1]
    atomic_write_text(out / PUBLIC_REJECTED, json.dumps(rejected, indent=1, sort_keys=True) + "\n")
    return recorded, rejected


def load_recordings(folder: Path | None = None) -> dict[str, RecordedProgram]:
    """Every shipped recording, by name (sorted).

    Raises
    ------
    ValueError
        If the folder holds none (re-record with ``make record``).
    """
    folder = recording_dir() if folder is None else Path(folder)
    paths = sorted(folder.glob("*.npz"))
    if not paths:
        raise ValueError(f"{folder} holds no recording: run `make record` (needs LinuxCNC)")
    return {p.stem: RecordedProgram.load(p) for p in paths}


def main() -> None:
    """``make record``: re-record the shipped set (and the public programs, where they lie
    beside the clone) and print one line per program."""
    recorded = record_set()
    if public_programs_dir().is_dir():
        public, rejected = record_public()
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
