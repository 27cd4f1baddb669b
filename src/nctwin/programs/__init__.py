"""Generators of the part programs the chapters need; each returns G-code text or a Toolpath."""

from __future__ import annotations

import os
from pathlib import Path

from ..cache import atomic_write_text

__all__ = ["write_programs"]


def write_programs(texts: dict[str, str], folder: str | os.PathLike) -> list[Path]:
    """Write programs as ``<folder>/<name>.nc`` (for a reader to open), each atomically;
    returns the paths."""
    return [atomic_write_text(Path(folder) / f"{name}.nc", text) for name, text in texts.items()]
