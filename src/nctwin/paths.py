"""Where the package finds its shipped data and writes its results.

The package is used from a clone (``pip install -e .``, as ``make`` does): shipped inputs live in
``data/`` at the top of the repository, reproduced tables in ``results/`` and generated caches in
``data/cache/``. ``NCTWIN_DATA`` and ``NCTWIN_RESULTS`` point elsewhere if set.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = [
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
    """Public part programs written by others (LinuxCNC's and CAMotics' examples), shipped in
    ``data/programs/public/`` byte for byte under their own licence (GPL, not the MIT code's);
    its README gives each file's origin, licence and SHA-256."""
    return data_dir() / "programs" / "public"
