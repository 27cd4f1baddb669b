"""The one content-hashed cache of generated data, and the one atomic write.

Generated data (simulations, trained networks) live under ``data/cache/<kind>/`` (see
:func:`nctwin.paths.cache_dir`), named by :func:`content_key`, a SHA-256 of everything they were
made from and of the CPU kernels numpy computes with (:func:`cache_path`). Every file the
package writes, cached or committed, goes through :func:`atomic_write`: to a temporary file in
the target folder, then ``os.replace``, so that an interrupted run never leaves a half-written
file behind.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from .paths import cache_dir

__all__ = [
    "atomic_savez",
    "atomic_write",
    "atomic_write_text",
    "cache_path",
    "content_key",
    "numpy_cpu_features",
]


def content_key(*parts: Any) -> str:
    """SHA-256 (hex) of ``parts``, in order.

    A ``str`` counts by its UTF-8 bytes, ``bytes`` as they are, an array by its dtype, shape and
    bytes (C order), anything else by its JSON (sorted keys; ``str()`` of what JSON cannot hold).
    """
    h = hashlib.sha256()
    for p in parts:
        if isinstance(p, np.ndarray):
            a = np.ascontiguousarray(p)
            h.update(f"array {a.dtype.str} {a.shape}".encode())
            h.update(a.tobytes())
        elif isinstance(p, bytes):
            h.update(b"bytes")
            h.update(p)
        elif isinstance(p, str):
            h.update(b"str")
            h.update(p.encode())
        else:
            h.update(b"json")
            h.update(json.dumps(p, sort_keys=True, default=str).encode())
    return h.hexdigest()


def numpy_cpu_features() -> tuple[str, ...]:
    """The CPU features numpy dispatches to here, sorted (``NPY_DISABLE_CPU_FEATURES`` turns
    some off): the same computation rounds differently where they differ."""
    from numpy._core._multiarray_umath import __cpu_features__

    return tuple(sorted(k for k, on in __cpu_features__.items() if on))


def cache_path(kind: str, name: str, key: str, suffix: str) -> Path:
    """``data/cache/<kind>/<name>-<16 hex digits><suffix>``: of ``key`` and of
    :func:`numpy_cpu_features`, so that data computed with other CPU kernels (a run outside
    ``make``, which pins them) is never read back as this run's."""
    return cache_dir() / kind / f"{name}-{content_key(key, numpy_cpu_features())[:16]}{suffix}"


def atomic_write(path: str | os.PathLike, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then rename it to ``path``.

    The temporary name ends with ``path``'s suffix (``np.savez`` and ``torch.save`` keep it).
    On any exception, interrupts included, the temporary file is removed and ``path`` is left as
    it was. Returns ``path``.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(
        dir=path.parent, prefix=f".{path.name}.", suffix=f".tmp{path.suffix}"
    )
    os.close(fd)
    try:
        write(Path(tmp))
        os.chmod(tmp, 0o644)  # mkstemp makes 0600; a results or cache file is for everyone to read
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def atomic_write_text(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` (UTF-8, newlines as given) to ``path`` atomically, synced to disk."""

    def write(tmp: Path) -> None:
        with tmp.open("w", encoding="utf-8", newline="") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())

    return atomic_write(path, write)


def atomic_savez(path: str | os.PathLike, **arrays: np.ndarray) -> Path:
    """``np.savez(path, **arrays)`` atomically (``path`` ends with ``.npz``)."""
    if Path(path).suffix != ".npz":
        raise ValueError(f"path = {str(path)!r} must end with .npz")
    return atomic_write(path, lambda tmp: np.savez(tmp, **arrays))
