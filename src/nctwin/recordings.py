"""Shipped recordings of a real NC kernel (LinuxCNC): their file format, and loading them.

LinuxCNC (:mod:`nctwin.kernel.linuxcnc`) is the measured machine. Its recordings of paper 1's
training programs (:func:`nctwin.programs.training.training_specs`, F 65-100 mm/s,
G64 P 0.05-0.5 mm), of a broader set (:data:`BROAD`), of CAM-style programs
(:func:`nctwin.programs.camstyle.cam_program`) and of the test programs (toolpaths I and II, the
pocket; F 75 and 92 mm/s, G64 P 0.3 and 0.4 mm) are shipped as a measurement, the way a
paper's data set would be, so that chapters use them without LinuxCNC. ``make record``
re-records them from nothing (:mod:`nctwin.record`; it needs ``make linuxcnc``);
:func:`load_recordings` reads them.

Public part programs written by others (``../shared/programs/``, GPL) are recorded the same way
(:func:`record_public`) and shipped as measurements only, without their text: a chapter that
uses them reads the text from where it lies and checks it against ``program_sha256``
(:func:`public_program_text`).

One compressed file per program, ``data/recordings/linuxcnc/<name>.npz``, with

* ``program``: the G-code text that was run (empty for a public program, which is not ours to
  ship), ``program_sha256``: the SHA-256 of that text, ``source``: where it comes from
  (``nctwin`` or ``public/<file name>``), ``machine``: the profile's name;
* ``junction_sample``, ``length_mm``, ``time_s``: the per-block targets
  (:func:`nctwin.targets.block_targets`, Chien et al. 2023, eq. 1-3);
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

from .motion import Motion
from .paths import data_dir, public_programs_dir
from .targets import BlockTargets

__all__ = [
    "MACHINE",
    "NAME",
    "PUBLIC_REJECTED",
    "TRACE_PERIOD_S",
    "RecordedProgram",
    "load_recordings",
    "public_program_text",
    "recording_dir",
    "rejected_file",
    "text_sha256",
    "trace_sha256",
]

#: Profile of the shipped recordings.
MACHINE = "linuxcnc_sim"

#: Name of the shipped recordings (their folder under ``data/recordings/``; a profile's
#: ``recordings`` key).
NAME = "linuxcnc"

#: Period of the shipped feed trace (s).
TRACE_PERIOD_S = 0.01


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
    return data_dir() / "recordings" / NAME


def trace_sha256(motion: Motion) -> str:
    """SHA-256 of a motion's positions (float64, C order): equal hashes, equal traces."""
    pos = np.ascontiguousarray(motion.pos_mm, dtype=np.float64)
    return hashlib.sha256(pos.tobytes()).hexdigest()


def text_sha256(text: str) -> str:
    """SHA-256 of a program text (UTF-8)."""
    return hashlib.sha256(text.encode()).hexdigest()


def rejected_file(prefix: str) -> str:
    """The file listing the programs of a recorded set (``prefix`` its recordings' prefix,
    ``public_`` or ``sample_``) that nctwin or LinuxCNC rejects, with the reason."""
    return f"{prefix}rejected.json"


#: The public programs' :func:`rejected_file`.
PUBLIC_REJECTED = rejected_file("public_")


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
