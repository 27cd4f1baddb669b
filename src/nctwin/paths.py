"""Where the package finds its shipped data and writes its results.

The package is used from a clone (``pip install -e .``, as ``make`` does): shipped inputs live in
``data/`` at the top of the repository, reproduced tables in ``results/`` and generated caches in
``data/cache/``. ``NCTWIN_DATA`` and ``NCTWIN_RESULTS`` point elsewhere if set.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = [
    "atomic_write_text",
    "cache_dir",
    "data_dir",
    "public_programs_dir",
    "repo_root",
    "results_dir",
]


def repo_root() -> Path:
    """Top of the repository this package was installed from."""
    return Path(__file__).resolve().parents[2]


def data_dir() -> Path:
    """Shipped inputs: paper tables, machine profiles, programs."""
    return Path(os.environ.get("NCTWIN_DATA", repo_root() / "data"))


def results_dir() -> Path:
    """Reproduced tables and claims, one folder per notebook."""
    return Path(os.environ.get("NCTWIN_RESULTS", repo_root() / "results"))


def cache_dir() -> Path:
    """Generated data, keyed by a hash of its parameters (not committed)."""
    return data_dir() / "cache"


def public_programs_dir() -> Path:
    """Public part programs written by others (``../shared/programs`` beside the clone, or
    ``NCTWIN_PUBLIC_PROGRAMS``). They are not shipped and may be absent."""
    default = repo_root().parent / "shared" / "programs"
    return Path(os.environ.get("NCTWIN_PUBLIC_PROGRAMS", default))


def atomic_write_text(path: Path, text: str) -> Path:
    """Write ``text`` to ``path`` via a temporary file in the same folder and ``os.replace``,
    so that an interrupted run never leaves a half-written file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
