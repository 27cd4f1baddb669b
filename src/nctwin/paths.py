"""Where the package finds its shipped data, keeps its caches and writes its results.

Shipped inputs (paper tables, machine profiles, programs, recordings, NIST's logs) travel with
the package: they are the folder ``data`` inside it, found through
:func:`importlib.resources.files`, so a wheel or a ``pip install --target`` copy finds them as a
clone does. In a clone,
``src/nctwin/data`` is a link to the repository's ``data/`` folder, where the files live.

Every folder can be moved by an environment variable, read at call time:

==================  ===================================================================
variable            default
==================  ===================================================================
``NCTWIN_DATA``     the package's ``data`` folder (in a clone: ``<repo>/data``)
``NCTWIN_CACHE``    ``<data>/cache`` in a clone or under ``NCTWIN_DATA``, where it can be
                    written; else ``$XDG_CACHE_HOME/nctwin`` (``~/.cache/nctwin``)
``NCTWIN_RESULTS``  ``<repo>/results`` in a clone; else ``results`` in the working folder
==================  ===================================================================

A clone (a source checkout) is recognised by the package's own location: its resolved folder is
``<root>/src/nctwin`` and ``<root>/pyproject.toml`` names the project ``nctwin``; an editable
install (``pip install -e .``, as ``make`` does) runs from it.
"""

from __future__ import annotations

import functools
import os
import tomllib
from importlib.resources import files
from pathlib import Path

__all__ = [
    "cache_dir",
    "data_dir",
    "linuxcnc_samples_dir",
    "nist_dir",
    "public_programs_dir",
    "repo_root",
    "results_dir",
    "source_root",
]

_PACKAGE = "nctwin"


@functools.cache
def source_root() -> Path | None:
    """The top of the source checkout the package runs from, or None for an installed copy.

    Returns
    -------
    Path or None
        ``<root>`` (resolved) where the package's resolved folder is ``<root>/src/nctwin`` and
        ``<root>/pyproject.toml`` names the project ``nctwin``; None otherwise (a wheel, a
        ``pip install --target`` copy).
    """
    package = Path(__file__).resolve().parent
    if package.name != _PACKAGE or package.parent.name != "src":
        return None
    root = package.parent.parent
    try:
        with (root / "pyproject.toml").open("rb") as fh:
            name = tomllib.load(fh).get("project", {}).get("name")
    except (OSError, tomllib.TOMLDecodeError):
        return None
    return root if name == _PACKAGE else None


def repo_root() -> Path:
    """The top of the source checkout, or the working folder for an installed copy.

    Returns
    -------
    Path
        :func:`source_root` where the package runs from a checkout (resolved, so that paths
        under :func:`data_dir` and :func:`cache_dir` are relative to it); else
        :meth:`pathlib.Path.cwd`, where :func:`results_dir` writes.
    """
    return source_root() or Path.cwd()


def shown(path: Path) -> Path:
    """``path`` as a reader should see it: relative to :func:`repo_root` where it lies under it.

    A cache or data folder set elsewhere (``NCTWIN_CACHE``, ``NCTWIN_DATA``) is shown whole.
    """
    try:
        return path.resolve().relative_to(repo_root())
    except ValueError:
        return path


def _package_data() -> Path:
    """The package's own ``data`` folder (resolved), or ``<root>/data`` in a checkout whose
    link ``src/nctwin/data`` is missing (a checkout without symbolic links)."""
    shipped = files(_PACKAGE) / "data"
    if not isinstance(shipped, Path):
        raise RuntimeError(
            f"nctwin's data ({shipped}) are not files on disk: install nctwin as a folder, not "
            "in a zip archive, or set NCTWIN_DATA to a copy of its data folder"
        )
    root = source_root()
    if not shipped.is_dir() and root is not None:
        return root / "data"
    return shipped.resolve()


def data_dir() -> Path:
    """Shipped inputs: paper tables, machine profiles, programs, recordings.

    Returns
    -------
    Path
        ``$NCTWIN_DATA`` if set, else the package's ``data`` folder (in a checkout it resolves
        to ``<repo>/data``). Holds ``machines/*.toml``, ``nist/``, ``papers/``, ``programs/``
        and ``recordings/``.
    """
    env = os.environ.get("NCTWIN_DATA")
    return Path(env) if env else _package_data()


def _user_cache() -> Path:
    """``$XDG_CACHE_HOME/nctwin`` if that variable holds an absolute path, else
    ``~/.cache/nctwin``."""
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    base = Path(xdg) if xdg and Path(xdg).is_absolute() else Path.home() / ".cache"
    return base / _PACKAGE


def cache_dir() -> Path:
    """Generated data (programs, recordings' derivatives, trained networks), keyed by a hash of
    their parameters; never committed, never shipped.

    Returns
    -------
    Path
        ``$NCTWIN_CACHE`` if set; else ``data_dir() / "cache"`` where the data are a checkout's
        or ``$NCTWIN_DATA``'s and that folder can be written (or made); else the per-user cache
        ``$XDG_CACHE_HOME/nctwin`` (default ``~/.cache/nctwin``), so that an installed copy
        never writes into its own installation. The folder need not exist yet.
    """
    env = os.environ.get("NCTWIN_CACHE")
    if env:
        return Path(env)
    data = data_dir()
    own_data = bool(os.environ.get("NCTWIN_DATA")) or source_root() is not None
    if own_data and _can_create(data / "cache"):
        return data / "cache"
    return _user_cache()


def _can_create(path: Path) -> bool:
    """Whether ``path`` is, or can be made, a writable folder: its nearest existing ancestor
    (itself included) is a writable folder."""
    for p in (path, *path.parents):
        if p.exists():
            return p.is_dir() and os.access(p, os.W_OK | os.X_OK)
    return False


def results_dir() -> Path:
    """Reproduced tables and claims, one folder per notebook.

    Returns
    -------
    Path
        ``$NCTWIN_RESULTS`` if set; else ``<repo>/results`` in a source checkout; else
        ``results`` in the current working folder.
    """
    env = os.environ.get("NCTWIN_RESULTS")
    return Path(env) if env else repo_root() / "results"


def public_programs_dir() -> Path:
    """Public part programs written by others (LinuxCNC's and CAMotics' examples), shipped in
    ``data/programs/public/`` byte for byte under their own licence (GPL, not the MIT code's);
    its README gives each file's origin, licence and SHA-256."""
    return data_dir() / "programs" / "public"


def linuxcnc_samples_dir() -> Path:
    """LinuxCNC's own sample programs (its ``nc_files/``) that nctwin reads and LinuxCNC's
    simulated mill runs, shipped in ``data/programs/public/samples/`` byte for byte (GPL); the
    public programs' README gives each file's origin and SHA-256."""
    return public_programs_dir() / "samples"


def nist_dir() -> Path:
    """NIST's SMS Test Bed data (public, NIST's notice): ``nc/`` (the 23 programs), ``logs/`` (80
    MTConnect logs of two Hurco VMX 24) and ``Devices.xml``, shipped in ``data/nist/`` byte for
    byte; its README gives the source, the notice and every file's SHA-256."""
    return data_dir() / "nist"
