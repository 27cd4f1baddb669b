"""Zhang et al.'s network on a reader's surface (the chapter's "Your surface" section).

A surface is a height grid in a CSV file, in mm: a header row of x coordinates (its first cell a
label, ignored), a first column of y coordinates, and the heights :math:`z(x, y)` in the cells,
readable by ``pandas.read_csv(path, index_col=0)``::

    y\\x,0,1,2,3,...
    0,5.0,5.1,5.3,5.6,...
    1,5.0,5.1,5.2,5.5,...

Both axes increase in equal steps (to 1 %), at least 4 values each; every cell is a finite
number. ``data/surfaces/examples/saddle.csv`` is an example (:func:`example_surface`), the one
the chapter's section shows when no surface of the reader's is given.

It is interpolated by a bicubic spline through the grid
(:class:`~nctwin.physics.surfaces.GridSurface`) and machined, as the chapter's surfaces, by an
iso-parametric ball-end path (:func:`~nctwin.physics.surfaces.iso_parametric_path`): lines
along x, at most ``stepover_mm`` apart, of cutter-contact points at most ``step_mm`` apart
(by default the chapter's counts and tool radius, read from
``data/papers/zhang2023_surfaces.csv``). The exact step error of every segment
(:func:`~nctwin.physics.steperror.step_error_um`) is the truth; the chapter's surface-1 networks
(never retrained here, nor fine-tuned to the surface) predict it from the segment's Table 1
samples, scored as the chapter scores surface 1: the share of segments whose absolute error is
below the paper's bars.
"""

from __future__ import annotations

import math
import numbers
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path

import numpy as np
import pandas as pd

from ..learn.train import Trained
from ..paths import data_dir
from ..physics.steperror import sample_columns, step_error_samples, step_error_um
from ..physics.surfaces import GridSurface, iso_parametric_path
from ..report.papers import load_paper_table
from .your_program import domain_notes, show_section
from .zhang2023_seeds import ensemble_um

__all__ = [
    "MAX_SEGMENTS",
    "SPACING_TOLERANCE",
    "SurfaceResult",
    "bars_um",
    "example_surface",
    "paper_path",
    "read_surface",
    "show_surface",
    "your_surface",
]


def example_surface() -> Path:
    """The shipped example surface, ``data/surfaces/examples/saddle.csv``."""
    return data_dir() / "surfaces" / "examples" / "saddle.csv"


#: Most path segments a reader's surface may have (the chapter's surfaces have 19,800).
MAX_SEGMENTS = 200_000

#: How far a grid's steps may differ from their mean, as a share of it (rounded coordinates).
SPACING_TOLERANCE = 0.01


@dataclass(frozen=True, eq=False)
class SurfaceResult:
    """The exact and the network's step errors of a reader's surface.

    Attributes
    ----------
    name : str
        The file's name.
    table : pandas.DataFrame
        One row per source (``exact``, ``network``): ``mean_um`` and ``max_um`` of the step
        error; for the network, ``abs_err_max_um`` and the share (%) of segments whose absolute
        error is below each bar (``share_below_<bar>um_pct``).
    notes : tuple of str
    cc_mm : ndarray, shape (n_lines, n_points, 3)
        The path's cutter-contact points.
    exact_um, network_um : ndarray, shape (n_lines, n_points - 1)
        Step error of every segment, line by line.
    reason : str or None
        Why the surface could not be run (one line), else None.
    """

    name: str
    table: pd.DataFrame = field(default_factory=pd.DataFrame)
    notes: tuple[str, ...] = ()
    cc_mm: np.ndarray | None = None
    exact_um: np.ndarray | None = None
    network_um: np.ndarray | None = None
    reason: str | None = None


def bars_um() -> tuple[float, float]:
    """The paper's absolute-error bars (um): Table 3's on surface 1 and the abstract's after
    fine-tuning, from the quantities of ``data/papers/zhang2023_summary.csv``."""
    names = load_paper_table("zhang2023_summary")["quantity"]
    found = [float(m.group(1).replace("p", ".")) for q in names
             if (m := re.search(r"abs_err_lt_(\d+(?:p\d+)?)um", q))]  # fmt: skip
    return tuple(sorted(set(found)))


def paper_path() -> tuple[float, int, int]:
    """The chapter's path on surface 1, from ``data/papers/zhang2023_surfaces.csv``:
    ``(tool_radius_mm, n_lines, n_points)``."""
    row = load_paper_table("zhang2023_surfaces").set_index("surface").loc[1]
    return float(row["tool_radius_mm"]), int(row["n_lines"]), int(row["n_cl_per_line"])


def _first_line(exc: Exception) -> str:
    return str(exc).splitlines()[0] if str(exc) else type(exc).__name__


def read_surface(path: str | PathLike) -> GridSurface:
    """The height grid of a CSV file (the module docstring's format).

    Raises
    ------
    ValueError
        ``"<file>: <reason>"`` in one line: a missing file, one that is not a CSV table, a cell
        that is empty or not a finite number (its line and column), axes that do not increase
        in equal steps, or fewer than 4 values on an axis.
    """
    p = Path(path)
    if p.is_dir():
        raise ValueError(f"{path}: is a directory, not a height grid")
    if not p.is_file():
        raise ValueError(f"{path}: no such file")
    try:  # no header: pandas would rename a repeated x ("3" -> "3.1")
        cells = pd.read_csv(p, header=None, dtype=str, skipinitialspace=True).to_numpy(object)
    except (ValueError, UnicodeDecodeError) as exc:  # pandas' parser errors are ValueErrors
        raise ValueError(f"{path}: not a CSV table ({_first_line(exc)})") from None
    if min(cells.shape) < 2:
        lines, columns = cells.shape
        raise ValueError(f"{path}: not a height grid: {lines} lines of {columns} comma-separated "
                         "columns, allowed a header row of x and a first column of y")  # fmt: skip
    cells[0, 0] = "0"  # the corner is a label
    values = pd.DataFrame(cells).apply(pd.to_numeric, errors="coerce").to_numpy(float)
    bad = ~np.isfinite(values)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        what = "empty" if pd.isna(cells[i, j]) else f"{cells[i, j]!r}, not a finite number"
        n = int(bad.sum())
        raise ValueError(f"{path}: line {i + 1}, column {j + 1} is {what} "
                         f"({n} bad cell{'s' if n > 1 else ''} in all)")  # fmt: skip
    try:
        surface = GridSurface(values[0, 1:], values[1:, 0], values[1:, 1:])
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None
    for name in ("x_mm", "y_mm"):
        steps = np.diff(getattr(surface, name))
        if np.ptp(steps) > SPACING_TOLERANCE * steps.mean():
            raise ValueError(f"{path}: {name} is not evenly spaced: steps {steps.min():g} to "
                             f"{steps.max():g} mm, allowed equal steps "
                             f"(to {SPACING_TOLERANCE:.0%})")  # fmt: skip
    return surface


def _real(value) -> bool:
    """Whether ``value`` is a finite real number (not a bool)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)


def _counts(surface: GridSurface, step_mm: float | None, stepover_mm: float | None,
            n_lines: int, n_points: int) -> tuple[int, int]:  # fmt: skip
    lx, ly = surface.size_mm
    for name, value, size in (("step_mm", step_mm, lx), ("stepover_mm", stepover_mm, ly)):
        if value is not None and not (_real(value) and 0 < value <= size):
            raise ValueError(f"{name} = {value!r} is out of range: allowed (0, {size:g}] mm")
    points = n_points if step_mm is None else math.ceil(lx / step_mm - 1e-9) + 1
    lines = n_lines if stepover_mm is None else math.ceil(ly / stepover_mm - 1e-9) + 1
    if lines * (points - 1) > MAX_SEGMENTS:
        raise ValueError(
            f"step_mm = {step_mm!r}, stepover_mm = {stepover_mm!r} give "
            f"{lines * (points - 1)} segments: allowed at most {MAX_SEGMENTS}"
        )
    return lines, points


def _check_radius(surface: GridSurface, tool_radius_mm: float, lines: int, points: int) -> None:
    """Refuse a ball larger than the surface's smallest concave radius of curvature at the grid
    points and the path's cutter-contact points: it would gouge the surface."""
    if not (_real(tool_radius_mm) and tool_radius_mm > 0):
        raise ValueError(f"tool_radius_mm = {tool_radius_mm!r} is out of range: allowed > 0")
    cc = surface.point(*np.meshgrid(np.linspace(0, 1, points), np.linspace(0, 1, lines)))
    kappa = max(
        float(surface.concave_curvature_per_mm(*np.meshgrid(surface.x_mm, surface.y_mm)).max()),
        float(surface.concave_curvature_per_mm(cc[..., 0], cc[..., 1]).max()),
    )
    if tool_radius_mm * kappa >= 1:
        raise ValueError(
            f"tool_radius_mm = {tool_radius_mm!r} is out of range: allowed (0, {1 / kappa:.4g}) "
            "mm, below the surface's smallest concave radius of curvature (a larger ball gouges)"
        )


def your_surface(
    path: str | PathLike,
    networks: Sequence[Trained],
    train_x: np.ndarray,
    *,
    tool_radius_mm: float | None = None,
    step_mm: float | None = None,
    stepover_mm: float | None = None,
) -> SurfaceResult:
    """The exact and the network's step errors of a reader's surface.

    Parameters
    ----------
    path : str or path-like
        A CSV height grid (the module docstring).
    networks : sequence of Trained
        The chapter's surface-1 networks; their mean is the prediction.
    train_x : ndarray, shape (n, 3 k + 13)
        Their training samples, for where the surface's samples leave them.
    tool_radius_mm : float, optional
        Ball radius, > 0 and below the surface's smallest concave radius of curvature; None:
        the paper's (:func:`paper_path`).
    step_mm, stepover_mm : float, optional
        Largest cutter-contact spacing along a line (x) and between lines (y), in (0, size of
        the grid]; the path spaces its points evenly. None: the chapter's counts of points per
        line and of lines over the surface (:func:`paper_path`).

    Returns
    -------
    SurfaceResult
        With ``reason`` set, and nothing else, where the file or a parameter is refused.
    """
    name = Path(path).name
    paper_radius_mm, n_lines, n_points = paper_path()
    radius_mm = paper_radius_mm if tool_radius_mm is None else tool_radius_mm
    try:
        surface = read_surface(path)
        lines, points = _counts(surface, step_mm, stepover_mm, n_lines, n_points)
        _check_radius(surface, radius_mm, lines, points)
    except ValueError as exc:
        return SurfaceResult(name, reason=str(exc))
    tool_path = iso_parametric_path(surface, n_lines=lines, n_points=points,
                                    tool_radius_mm=radius_mm)  # fmt: skip
    exact = step_error_um(tool_path).error_um
    k = (networks[0].model.layers[0].in_features - 13) // 3
    x = step_error_samples(tool_path, k)
    predicted = ensemble_um(networks, x)
    err = np.abs(predicted - exact)
    table = pd.DataFrame([
        {"source": "exact", "mean_um": exact.mean(), "max_um": exact.max()},
        {"source": "network", "mean_um": predicted.mean(), "max_um": predicted.max(),
         "abs_err_max_um": err.max(),
         **{f"share_below_{b:g}um_pct": 100 * float(np.mean(err < b)) for b in bars_um()}},
    ])  # fmt: skip
    col = {c: i for i, c in enumerate(sample_columns(k))}
    cc0, cc1 = [col[f"cc0_{c}"] for c in "xyz"], [col[f"cc1_{c}"] for c in "xyz"]

    def reach(a: np.ndarray) -> np.ndarray:  # CC spacing, R and the CL height of each segment
        return np.column_stack([np.linalg.norm(a[:, cc1] - a[:, cc0], axis=1), a[:, col["R"]],
                                a[:, col["cl0_z"]]])  # fmt: skip

    lx, ly = surface.size_mm
    seeds = "one seed" if len(networks) == 1 else f"the mean of {len(networks)} seeds"
    notes = (
        f"{lines} lines {ly / max(lines - 1, 1):.3g} mm apart of {points} cutter-contact points "
        f"{lx / (points - 1):.3g} mm apart, {len(exact)} segments, R = {radius_mm:g} mm; the "
        f"network is surface 1's ({seeds}), not fine-tuned to this surface.",
        *domain_notes(reach(x), reach(train_x), ("CC spacing (mm)", "R (mm)", "CL z (mm)"),
                      rows="segments"),
    )  # fmt: skip
    shape = (lines, points - 1)
    return SurfaceResult(name, table, notes, tool_path.cc_mm, exact.reshape(shape),
                         predicted.reshape(shape))  # fmt: skip


def show_surface(result: SurfaceResult) -> None:
    """Display the "Your surface" section: a heading, then the reason, or the table, the notes
    and the exact step error, the network's and their difference over the surface."""
    if show_section(f"Your surface: `{result.name}`", result.reason, result.table, result.notes):
        _plot_surface(result)


def _plot_surface(result: SurfaceResult) -> None:
    import matplotlib.pyplot as plt

    x, y = result.cc_mm[:, :-1, 0], result.cc_mm[:, :-1, 1]  # each segment at its start
    diff = result.network_um - result.exact_um
    top = max(result.exact_um.max(), result.network_um.max())
    half = float(np.abs(diff).max())
    fig, axes = plt.subplots(1, 3, figsize=(13, 4), constrained_layout=True)
    for ax, values, title, style in (
        (axes[0], result.exact_um, "exact step error (um)", {"vmin": 0, "vmax": top}),
        (axes[1], result.network_um, "network's step error (um)", {"vmin": 0, "vmax": top}),
        (axes[2], diff, "network minus exact (um)",
         {"cmap": "coolwarm", "vmin": -half, "vmax": half}),
    ):  # fmt: skip
        image = ax.pcolormesh(x, y, values, shading="auto", **style)
        ax.set(title=title, xlabel="x (mm)", ylabel="y (mm)", aspect="equal")
        fig.colorbar(image, ax=ax, shrink=0.8)
    fig.suptitle(result.name)
    plt.show()
