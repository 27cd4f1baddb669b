"""Shipped recordings of a real NC kernel (LinuxCNC): record them, save them, load them.

LinuxCNC (:mod:`nctwin.kernel.linuxcnc`) is the measured machine. Its recordings of paper 1's
training programs (:func:`nctwin.programs.training.training_specs`, F 65-100 mm/s,
G64 P 0.05-0.5 mm) and test programs (toolpaths I and II, the pocket; F 75 and 92 mm/s,
G64 P 0.3 and 0.4 mm) are shipped as a measurement, the way a paper's data set would be, so
that chapters use them without LinuxCNC. ``make record`` re-records them from nothing (it needs
``make linuxcnc``); :func:`load_recordings` reads them.

One compressed file per program, ``data/recordings/linuxcnc/<name>.npz``, with

* ``program``: the G-code text that was run, ``machine``: the profile's name;
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
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from joblib import Parallel, delayed
from tqdm import tqdm

from .features import BlockTargets, block_targets
from .gcode import parse
from .machine import MachineProfile, load_machine
from .motion import Motion
from .paths import data_dir
from .programs.pocket import pocket_program
from .programs.training import contour_program, training_specs

__all__ = [
    "MACHINE",
    "TRACE_PERIOD_S",
    "RecordedProgram",
    "load_recordings",
    "record_program",
    "record_set",
    "recording_dir",
    "recording_programs",
    "trace_sha256",
]

#: Profile of the shipped recordings.
MACHINE = "linuxcnc_sim"
#: Period of the shipped feed trace (s).
TRACE_PERIOD_S = 0.01
#: The shipped set: seed and size of :func:`~nctwin.programs.training.training_specs`.
RECORD_SEED = 9
N_PROGRAMS = 6
N_LINES = 200
FEED_RANGE_MM_S = (65.0, 100.0)
TOL_RANGE_MM = (0.05, 0.5)
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
    """

    name: str
    program: str
    machine: str
    targets: BlockTargets
    feed_mm_s: np.ndarray
    n_samples: int
    trace_sha256: str

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
            )


def recording_dir() -> Path:
    """Folder of the shipped LinuxCNC recordings."""
    return data_dir() / "recordings" / "linuxcnc"


def recording_programs() -> dict[str, str]:
    """The shipped set: name -> G-code text (see the module docstring)."""
    specs = training_specs(
        RECORD_SEED,
        n_programs=N_PROGRAMS,
        n_lines=N_LINES,
        feed_range_mm_s=FEED_RANGE_MM_S,
        tol_range_mm=TOL_RANGE_MM,
    )
    out = {f"train_{i:02d}_{s.family}": s.text() for i, s in enumerate(specs)}
    for name in ("I", "II", "pocket"):
        for f in TEST_FEEDS_MM_S:
            for e in TEST_TOLS_MM:
                text = (
                    pocket_program(feed_mm_s=f, tol_mm=e)
                    if name == "pocket"
                    else contour_program(name, feed_mm_s=f, tol_mm=e)
                )
                out[f"test_{name}_F{f:g}_P{e:g}"] = text
    return out


def trace_sha256(motion: Motion) -> str:
    """SHA-256 of a motion's positions (float64, C order): equal hashes, equal traces."""
    pos = np.ascontiguousarray(motion.pos_mm, dtype=np.float64)
    return hashlib.sha256(pos.tobytes()).hexdigest()


def record_program(
    name: str, program: str, machine: MachineProfile, *, speed: float = 5
) -> RecordedProgram:
    """Record one program on LinuxCNC and reduce it to what is shipped.

    Raises what :func:`nctwin.kernel.linuxcnc.run` raises.
    """
    from .kernel import linuxcnc

    tp = parse(program)
    motion = linuxcnc.run(program, machine, speed=speed)
    step = round(TRACE_PERIOD_S / motion.period_s)
    return RecordedProgram(
        name=name,
        program=program,
        machine=machine.name,
        targets=block_targets(motion, tp),
        feed_mm_s=motion.speed_mm_s[::step].astype(np.float32),
        n_samples=len(motion),
        trace_sha256=trace_sha256(motion),
    )


def record_set(
    folder: Path | None = None, *, n_jobs: int = 2, speed: float = 5
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
    """
    if not isinstance(n_jobs, int) or n_jobs < 1:
        raise ValueError(f"n_jobs = {n_jobs!r} is out of range: allowed integers >= 1")
    folder = recording_dir() if folder is None else Path(folder)
    machine = load_machine(MACHINE)
    programs = recording_programs()
    jobs = (delayed(record_program)(n, t, machine, speed=speed) for n, t in programs.items())
    parallel = Parallel(n_jobs=n_jobs, backend="threading", return_as="generator")
    out = []
    for rec in tqdm(parallel(jobs), total=len(programs), desc="LinuxCNC", mininterval=5.0):
        rec.save(folder)
        out.append(rec)
    return out


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
    """``make record``: re-record the shipped set and print one line per program."""
    for rec in record_set():
        print(
            f"record: {rec.name}: {len(rec.targets.time_s)} blocks, "
            f"{rec.cycle_time_s:.3f} s, sha256 {rec.trace_sha256[:12]}"
        )
    print(f"record: {recording_dir()}")


if __name__ == "__main__":
    main()
