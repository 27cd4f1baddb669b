"""A reader's surface in the Zhang et al. chapter: the grid surface, its reader, the section."""

from __future__ import annotations

import matplotlib
import numpy as np
import pytest

from nctwin.chapters import zhang2023_yours as zy
from nctwin.chapters.zhang2023 import variant_configs
from nctwin.learn.train import fit
from nctwin.paths import data_dir
from nctwin.physics.steperror import step_error_samples, step_error_um
from nctwin.physics.surfaces import GridSurface, iso_parametric_path

EXAMPLE = data_dir() / "surfaces" / "examples" / "saddle.csv"
#: A 4 x 4 grid, x and y 0 to 3 mm, with ``{}`` for the cell at x = 1, y = 1.
GRID = "y\\x,0,1,2,3\n0,1,1,1,1\n1,1,{},1,1\n2,1,1,1,1\n3,1,1,1,1\n"


def test_a_plane_has_no_step_error_and_a_cylinder_its_closed_form():
    x, y = np.linspace(0, 40, 41), np.linspace(0, 30, 31)
    plane = GridSurface(x, y, np.full((31, 41), 2.0))
    path = iso_parametric_path(plane, n_lines=4, n_points=11, tool_radius_mm=5.0)
    assert np.abs(step_error_um(path).error_um).max() < 1e-6
    # a convex cylinder of radius rho sampled every 0.5 mm: the CC points at x = 0 and 4 mm
    # subtend asin(4 / rho), and the ball of radius R leaves (rho + R)(1 - cos(half of it))
    rho, r = 50.0, 5.0
    xs = np.linspace(-20, 20, 81)
    cylinder = GridSurface(xs, y, np.tile(np.sqrt(rho**2 - xs**2), (31, 1)))
    e = step_error_um(iso_parametric_path(cylinder, n_lines=3, n_points=11,
                                          tool_radius_mm=r)).error_um  # fmt: skip
    half = np.arcsin(4.0 / rho) / 2
    assert e[4:6] == pytest.approx((rho + r) * (1 - np.cos(half)) * 1000, rel=1e-3)


def test_concave_curvature_is_one_over_the_radius_of_a_valley_and_none_on_a_ridge():
    rho, xs, y = 20.0, np.linspace(-15, 15, 61), np.linspace(0, 30, 31)
    valley = np.tile(rho - np.sqrt(rho**2 - xs**2), (31, 1))
    inner = np.meshgrid(xs[2:-2], y)  # away from the spline's free ends
    kappa = GridSurface(xs, y, valley).concave_curvature_per_mm(*inner)
    assert kappa == pytest.approx(1 / rho, rel=1e-2)
    assert np.abs(GridSurface(xs, y, -valley).concave_curvature_per_mm(*inner)).max() < 1e-9


def test_grid_surface_refuses_a_grid_it_cannot_interpolate():
    with pytest.raises(ValueError, match="x_mm is out of range: allowed at least 4"):
        GridSurface([0, 1, 2], [0, 1, 2, 3], np.zeros((4, 3)))
    with pytest.raises(ValueError, match="y_mm is out of range"):
        GridSurface([0, 1, 2, 3], [0, 2, 1, 3], np.zeros((4, 4)))
    with pytest.raises(ValueError, match=r"z_mm has shape \(4, 5\): allowed \(4, 4\)"):
        GridSurface([0, 1, 2, 3], [0, 1, 2, 3], np.zeros((4, 5)))


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        (GRID.format("a"), "line 3, column 3 is 'a', not a finite number (1 bad cell in all)"),
        (GRID.format(""), "line 3, column 3 is empty"),
        (GRID.format("inf"), "line 3, column 3 is 'inf', not a finite number"),
        (GRID.format("1") + "4,1,1\n", "line 6, column 4 is empty (2 bad cells in all)"),
        (GRID.format("1,1"), "not a CSV table (Error tokenizing data"),
        ("", "not a CSV table (No columns to parse from file)"),
        ("a;b;c\n1;2;3\n", "not a height grid: 2 lines of 1 comma-separated columns"),
        (GRID.format("1").replace("0,1,2,3\n", "0,1,2\n"), "not a CSV table"),
        ("y\\x,0,1,2\n0,1,1,1\n1,1,1,1\n2,1,1,1\n3,1,1,1\n", "x_mm is out of range"),
        (GRID.format("1").replace("\n2,", "\n1,"), "y_mm is out of range"),
        (GRID.format("1").replace("0,1,2,3\n", "0,1,2,2\n"), "x_mm is out of range"),
        (GRID.format("1").replace("0,1,2,3\n", "0,1,3,4\n"),
         "x_mm is not evenly spaced: steps 1 to 2 mm, allowed equal steps (to 1%)"),
    ],
)  # fmt: skip
def test_read_surface_says_in_one_line_why(tmp_path, text, reason):
    path = tmp_path / "s.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError) as err:
        zy.read_surface(path)
    assert str(err.value).startswith(f"{path}: ") and reason in str(err.value)
    assert "\n" not in str(err.value)


def test_read_surface_refuses_a_missing_file_and_a_directory(tmp_path):
    with pytest.raises(ValueError, match=r"nope\.csv: no such file$"):
        zy.read_surface(tmp_path / "nope.csv")
    with pytest.raises(ValueError, match=r"is a directory, not a height grid$"):
        zy.read_surface(tmp_path)


def test_the_example_surface_reads(tmp_path):
    surface = zy.read_surface(EXAMPLE)
    assert surface.size_mm == (40.0, 30.0)
    assert surface.height_mm(20.0, 15.0) == pytest.approx(10.0 + 2 * np.exp(-(64 + 25) / 30),
                                                         abs=1e-4)  # fmt: skip
    # rounded coordinates pass as evenly spaced: a third of a mm to 3 decimals
    thirds = np.round(np.arange(6) / 3, 3)
    assert np.ptp(np.diff(thirds)) > 0
    assert zy.read_surface(_grid_file(tmp_path, thirds)).size_mm == (1.667, 1.667)


def _grid_file(folder, axis):
    """A flat CSV grid with ``axis`` as x and y, in ``folder``."""
    rows = [",".join(["y\\x", *map(str, axis)])]
    rows += [",".join([str(v), *["0"] * len(axis)]) for v in axis]
    path = folder / "grid.csv"
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


def test_bars_and_path_are_the_papers():
    assert zy.bars_um() == (0.5, 1.0)
    assert zy.paper_path() == (5.0, 200, 100)


@pytest.fixture(scope="module")
def tiny_net():
    """A small network on samples of a sphere-like grid (the chapter's input width)."""
    x = np.linspace(0, 40, 21)
    surface = GridSurface(x, x, 20 - 0.005 * ((x[None, :] - 20) ** 2 + (x[:, None] - 20) ** 2))
    path = iso_parametric_path(surface, n_lines=20, n_points=20, tool_radius_mm=5.0)
    xs = step_error_samples(path, 2)
    ys = step_error_um(path).error_um[:, None]
    model, config = variant_configs(xs.shape[1], max_epochs=3, patience=2)
    net = fit(model, config, np.array_split(xs, 19), np.array_split(ys, 19),
              name="test_zhang_yours", progress=False, cache=False)  # fmt: skip
    return net, xs


def test_your_surface_end_to_end(tiny_net, capsys, monkeypatch):
    net, xs = tiny_net
    result = zy.your_surface(EXAMPLE, [net], xs, step_mm=2.0, stepover_mm=3.0)
    assert result.reason is None
    assert result.exact_um.shape == result.network_um.shape == (11, 20)  # 30/3+1, 40/2
    assert result.cc_mm.shape == (11, 21, 3)
    assert list(result.table.source) == ["exact", "network"]
    err = np.abs(result.network_um - result.exact_um)
    assert result.table.share_below_1um_pct[1] == pytest.approx(100 * np.mean(err < 1.0))
    assert result.notes[0].startswith(
        "11 lines 3 mm apart of 21 cutter-contact points 2 mm apart, 220 segments, R = 5 mm"
    )
    # a step that does not divide the grid: the path's points are closer, never farther
    assert zy.your_surface(EXAMPLE, [net], xs, step_mm=3.0, stepover_mm=7.0).exact_um.shape == (
        6, 14)  # fmt: skip
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shown = []
    monkeypatch.setattr(plt, "show", lambda: shown.append(plt.gcf()))
    zy.show_surface(result)
    out = capsys.readouterr().out
    assert "share_below_0.5um_pct" in out and "not run" not in out
    titles = [ax.get_title() for ax in shown[0].axes if ax.get_label() != "<colorbar>"]
    assert titles == ["exact step error (um)", "network's step error (um)",
                      "network minus exact (um)"]  # fmt: skip
    plt.close(shown[0])


@pytest.mark.parametrize(
    ("kwargs", "reason"),
    [
        ({"tool_radius_mm": 0.0}, "tool_radius_mm = 0.0 is out of range: allowed > 0"),
        ({"tool_radius_mm": float("nan")}, "tool_radius_mm = nan is out of range: allowed > 0"),
        # the saddle's bump is ringed by a valley of radius 12.8 mm (its smallest)
        ({"tool_radius_mm": 13.0},
         "tool_radius_mm = 13.0 is out of range: allowed (0, 12.8"),
        ({"step_mm": 50.0}, "step_mm = 50.0 is out of range: allowed (0, 40] mm"),
        ({"stepover_mm": -1.0}, "stepover_mm = -1.0 is out of range: allowed (0, 30] mm"),
        ({"step_mm": "2"}, "step_mm = '2' is out of range: allowed (0, 40] mm"),
        ({"step_mm": 0.01, "stepover_mm": 0.01},
         f"segments: allowed at most {zy.MAX_SEGMENTS}"),
    ],
)  # fmt: skip
def test_your_surface_refuses_a_parameter_in_one_line(tiny_net, kwargs, reason, capsys):
    net, xs = tiny_net
    result = zy.your_surface(EXAMPLE, [net], xs, **kwargs)
    assert reason in result.reason and result.table.empty and "\n" not in result.reason
    zy.show_surface(result)
    assert capsys.readouterr().out.endswith(f"not run: {result.reason}\n")
