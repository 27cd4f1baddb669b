"""Zhang et al.'s network on a reader's surface (the chapter's "Your surface" section).

A surface is a height grid in a CSV file, in mm: a header row of x coordinates, a first column
of y coordinates, and the heights :math:`z(x, y)` in the cells, readable by
``pandas.read_csv(path, index_col=0)``::

    y\\x,0,1,2,3,...
    0,5.0,5.1,5.3,5.6,...
    1,5.0,5.1,5.2,5.5,...

It is interpolated by a bicubic spline through the grid
(:class:`~nctwin.physics.surfaces.GridSurface`) and machined, as the chapter's surfaces, by an
iso-parametric ball-end path (:func:`~nctwin.physics.surfaces.iso_parametric_path`): lines
along x, ``stepover_mm`` apart, of cutter-contact points ``step_mm`` apart. The exact step
error of every segment (:func:`~nctwin.physics.steperror.step_error_um`) is the truth; the
chapter's surface-1 networks (never retrained here, nor fine-tuned to the surface) predict it
from the segment's Table 1 samples, scored as the chapter scores surface 1: the share of
segments whose absolute error is below the paper's bars.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path

import numpy as np
import pandas as pd

from ..learn.train import Trained
from ..physics.steperror import sample_columns, step_error_samples, step_error_um
from ..physics.surfaces import GridSurface, iso_parametric_path
from ..report.tables import load_paper_table, show
from .your_program import domain_notes
from .zhang2023_seeds import ensemble_um

__all__ = [
    "MAX_SEGMENTS",
    "SurfaceResult",
    "bars_um",
    "read_surface",
    "show_surface",
    "your_surface",
]

#: Most path segments a reader's surface may have (the chapter's surfaces have 19,800).
MAX_SEGMENTS = 200_000


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
    exact_um, network_um : ndarray, shape (n_lines, n_points - 1)
        Step error of every segment, line by line.
    reason : str or None
        Why the surface could not be run (one line), else None.
    """

    name: str
    table: pd.DataFrame = field(default_factory=pd.DataFrame)
    notes: tuple[str, ...] = ()
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


def read_surface(path: str | PathLike) -> GridSurface:
    """The height grid of a CSV file (the module docstring's format).

    Raises
    ------
    ValueError
        ``"<file>: <reason>"``: a file that cannot be read, cells that are not numbers, or a
        grid :class:`~nctwin.physics.surfaces.GridSurface` refuses.
    """
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"{path}: no such file")
    try:
        grid = pd.read_csv(p, index_col=0)
        x = pd.to_numeric(pd.Index(grid.columns), errors="raise").to_numpy(float)
        y = pd.to_numeric(grid.index, errors="raise").to_numpy(float)
        z = grid.apply(pd.to_numeric, errors="raise").to_numpy(float)
    except (ValueError, UnicodeDecodeError, pd.errors.ParserError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ValueError(f"{path}: not a height grid of numbers ({first})") from None
    try:
        return GridSurface(x, y, z)
    except ValueError as exc:
        raise ValueError(f"{path}: {exc}") from None


def _counts(surface: GridSurface, step_mm: float | None, stepover_mm: float | None,
            n_lines: int, n_points: int) -> tuple[int, int]:  # fmt: skip
    lx, ly = surface.size_mm
    for name, value, size in (("step_mm", step_mm, lx), ("stepover_mm", stepover_mm, ly)):
        if value is not None and not (0 < value <= size):
            raise ValueError(f"{name} = {value!r} is out of range: allowed (0, {size:g}] mm")
    points = n_points if step_mm is None else math.floor(lx / step_mm + 1e-9) + 1
    lines = n_lines if stepover_mm is None else math.floor(ly / stepover_mm + 1e-9) + 1
    if lines * (points - 1) > MAX_SEGMENTS:
        raise ValueError(
            f"step_mm = {step_mm!r}, stepover_mm = {stepover_mm!r} give "
            f"{lines * (points - 1)} segments: allowed at most {MAX_SEGMENTS}"
        )
    return lines, points


def your_surface(
    path: str | PathLike,
    networks: Sequence[Trained],
    train_x: np.ndarray,
    *,
    tool_radius_mm: float = 5.0,
    step_mm: float | None = None,
    stepover_mm: float | None = None,
    n_lines: int = 200,
    n_points: int = 100,
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
    tool_radius_mm : float
        Ball radius, > 0.
    step_mm, stepover_mm : float, optional
        Cutter-contact spacing along a line and between lines; None: ``n_points`` points per
        line and ``n_lines`` lines over the surface (the chapter's path).

    Returns
    -------
    SurfaceResult
        With ``reason`` set, and nothing else, where the file or a parameter is refused.
    """
    name = Path(path).name
    try:
        if not (math.isfinite(tool_radius_mm) and tool_radius_mm > 0):
            raise ValueError(f"tool_radius_mm = {tool_radius_mm!r} is out of range: allowed > 0")
        surface = read_surface(path)
        lines, points = _counts(surface, step_mm, stepover_mm, n_lines, n_points)
    except ValueError as exc:
        return SurfaceResult(name, reason=str(exc))
    tool_path = iso_parametric_path(surface, n_lines=lines, n_points=points,
                                    tool_radius_mm=tool_radius_mm)  # fmt: skip
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

    notes = (
        f"{lines} lines of {points} cutter-contact points, {len(exact)} segments, R = "
        f"{tool_radius_mm:g} mm; the networks are surface 1's ({len(networks)} seeds, their "
        "mean), not fine-tuned to this surface.",
        *domain_notes(reach(x), reach(train_x), ("CC spacing (mm)", "R (mm)", "CL z (mm)"),
                      rows="segments"),
    )  # fmt: skip
    shape = (lines, points - 1)
    return SurfaceResult(name, table, notes, exact.reshape(shape), predicted.reshape(shape))


def show_surface(result: SurfaceResult) -> None:
    """Display the "Your surface" section: a heading, then the reason, or the table, the notes
    and the exact step error beside the network's error over the path."""
    import matplotlib.pyplot as plt
    from IPython.display import Markdown, display

    display(Markdown(f"## Your surface: `{result.name}`"))
    if result.reason is not None:
        print(f"not run: {result.reason}")
        return
    show(result.table)
    for note in result.notes:
        print(note)
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), constrained_layout=True)
    for ax, values, title, cmap in (
        (axes[0], result.exact_um, "exact step error (um)", "viridis"),
        (axes[1], result.network_um - result.exact_um, "network minus exact (um)", "coolwarm"),
    ):
        lim = {"vmin": -np.abs(values).max(), "vmax": np.abs(values).max()} if cmap == "coolwarm" \
            else {}  # fmt: skip
        image = ax.imshow(values, aspect="auto", origin="lower", cmap=cmap, **lim)
        ax.set(xlabel="segment along the line", ylabel="line", title=title)
        fig.colorbar(image, ax=ax)
    plt.show()
