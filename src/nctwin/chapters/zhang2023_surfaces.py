"""The surfaces of the Zhang et al. (2023) chapter (:mod:`nctwin.chapters.zhang2023`): each
surface's path, exact step errors and Table 1 samples, its sizes beside the paper's, and the exact
method against the chord formula. Nothing here trains a network.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import pandas as pd

from ..physics.steperror import (
    StepError,
    chord_step_error_um,
    inner_points_for_hidden_width,
    step_error_samples,
    step_error_um,
)
from ..physics.surfaces import Cylinder, Sphere, ToolPath, iso_parametric_path, paper_surface
from ..report.papers import load_paper_table, side_by_side

__all__ = ["SurfaceData", "chord_check", "paper_hidden", "surface_data", "surfaces_table"]


@functools.cache
def paper_hidden() -> tuple[int, int]:
    """Hidden layer widths of the paper (Sec. "Network parameter determination"), read from
    ``data/papers/zhang2023_summary.csv`` when first asked (a worker process of the runner may
    see another data folder)."""
    summary = load_paper_table("zhang2023_summary").set_index("quantity")
    return tuple(int(summary.loc[q, "value"])
                 for q in ("hidden_layer1_neurons", "hidden_layer2_neurons"))  # fmt: skip


@dataclass(frozen=True, eq=False)
class SurfaceData:
    """One surface's path, exact step errors and network samples.

    Parameters
    ----------
    index : int
        Surface 1, 2 or 3.
    path : ToolPath
    exact : StepError
        Exact step errors, shape (n,): one per segment.
    x : ndarray, shape (n, 3 k + 13)
        Table 1 samples.
    """

    index: int
    path: ToolPath
    exact: StepError
    x: np.ndarray

    @property
    def y_um(self) -> np.ndarray:
        """Targets, the exact step errors in um, shape (n, 1)."""
        return self.exact.error_um[:, None]


def surface_data(index: int, *, n_inner: int | None = None) -> SurfaceData:
    """Path, exact step errors and samples of surface ``index`` (the paper's path).

    ``n_inner`` defaults to :func:`nctwin.physics.steperror.inner_points_for_hidden_width` of
    :func:`paper_hidden` [0] (104 inner points, 325 inputs).
    """
    k = inner_points_for_hidden_width(paper_hidden()[0]) if n_inner is None else n_inner
    path = iso_parametric_path(paper_surface(index))
    return SurfaceData(index, path, step_error_um(path), step_error_samples(path, k))


def surfaces_table(data: dict[int, SurfaceData], paper_surfaces: pd.DataFrame) -> pd.DataFrame:
    """The surfaces' sizes and step-error ranges beside the paper's (Fig. 4).

    Parameters
    ----------
    data : dict
        ``surface -> SurfaceData``.
    paper_surfaces : pandas.DataFrame
        The paper table ``zhang2023_surfaces``.

    Returns
    -------
    pandas.DataFrame
        One row per surface: ``x_mm``, ``y_mm`` (extent of the CC points), ``z_max_mm``,
        ``segments``, ``err_min_um``, ``err_max_um``, ``below_0p01um_pct``, ``convex_pct``
        (rounded to 4 decimals), beside the paper's bounding box, sample count and step-error
        range (:func:`~nctwin.report.papers.side_by_side`).
    """
    ours = pd.DataFrame(
        [
            {
                "surface": i,
                "x_mm": np.ptp(d.path.cc_mm[..., 0]),
                "y_mm": np.ptp(d.path.cc_mm[..., 1]),
                "z_max_mm": d.path.surface.size_z_mm,
                "segments": d.path.n_segments,
                "err_min_um": d.exact.error_um.min(),
                "err_max_um": d.exact.error_um.max(),
                "below_0p01um_pct": 100 * np.mean(d.exact.error_um < 0.01),
                "convex_pct": 100 * d.exact.convex.mean(),
            }
            for i, d in data.items()
        ]
    ).round(4)
    return side_by_side(
        ours, paper_surfaces, on=["surface"],
        columns=["bbox_x_mm", "bbox_y_mm", "bbox_z_mm", "n_samples", "step_err_min_um",
                 "step_err_max_um"],
    )  # fmt: skip


def chord_check() -> pd.DataFrame:
    r"""The exact method against the chord formula
    :math:`e = (\rho \pm R)(1 - \cos\frac{\Delta\theta}{2})`.

    Sphere and cylinder of radius 40 mm, tool (R = 5 mm) outside (convex) and inside (concave),
    10 lines of 30 CC points (:func:`~nctwin.physics.surfaces.iso_parametric_path`).

    Returns
    -------
    pandas.DataFrame
        One row per shape and tool side: ``shape``, ``tool``, ``chord_formula_um``,
        ``max_abs_diff_um`` (largest difference over the 10 x 29 segments), ``below_1e-6um`` and
        ``classified_convex_pct``.
    """
    rows = []
    shapes = (Sphere(40.0), Sphere(40.0, inside=True), Cylinder(40.0), Cylinder(40.0, inside=True))
    for shape in shapes:
        path = iso_parametric_path(shape, n_lines=10, n_points=30)
        reference = chord_step_error_um(40.0, 5.0, shape.sweep_rad / 29, inside=shape.inside)
        result = step_error_um(path)
        rows.append(
            {
                "shape": type(shape).__name__.lower(),
                "tool": "inside" if shape.inside else "outside",
                "chord_formula_um": float(reference),
                "max_abs_diff_um": float(np.max(np.abs(result.error_um - reference))),
                "below_1e-6um": bool(np.max(np.abs(result.error_um - reference)) < 1e-6),
                "classified_convex_pct": 100 * result.convex.mean(),
            }
        )
    return pd.DataFrame(rows)
