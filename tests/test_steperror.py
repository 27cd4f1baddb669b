"""Exact step error (Zhang et al. 2023, eq. 1) against the chord formula, the iterative method
and the paper's sample layout (Table 1, eq. 8)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from nctwin.physics.steperror import (
    chord_step_error_um,
    inner_points_for_hidden_width,
    sample_columns,
    step_error_iterative_um,
    step_error_samples,
    step_error_um,
)
from nctwin.physics.surfaces import (
    BumpSurface,
    Cylinder,
    Sphere,
    iso_parametric_path,
    paper_surface,
)
from nctwin.report.papers import load_paper_table

TOL_UM = 1e-6  # the accuracy the exact method promises


def _reference(surface, n_points: int, radius_mm: float) -> np.ndarray:
    angle = surface.sweep_rad / (n_points - 1)
    return chord_step_error_um(surface.radius_mm, radius_mm, angle, inside=surface.inside)


@pytest.mark.parametrize("inside", [False, True])
@pytest.mark.parametrize("kind", [Sphere, Cylinder])
def test_matches_the_chord_formula_on_sphere_and_cylinder(kind, inside: bool) -> None:
    surface = kind(40.0, inside=inside)
    path = iso_parametric_path(surface, n_lines=7, n_points=30)
    result = step_error_um(path)
    # by hand: rho = 40, R = 5, step angle = sweep / 29; e = (rho +- R)(1 - cos(angle / 2))
    angle = surface.sweep_rad / 29
    by_hand = (45.0 if not inside else 35.0) * (1 - math.cos(angle / 2)) * 1000
    np.testing.assert_allclose(result.error_um, by_hand, rtol=0, atol=TOL_UM)
    assert np.all(result.convex != inside)
    # the critical point is the middle of the arc (by symmetry)
    seg = path.segments()
    np.testing.assert_allclose(result.u_critical, 0.5 * (seg["u0"] + seg["u1"]), atol=1e-6)


@given(
    radius_mm=st.floats(8.0, 200.0),
    tool_radius_mm=st.floats(0.5, 6.0),
    sweep_rad=st.floats(0.2, 2.5),
    n_points=st.integers(5, 60),
    inside=st.booleans(),
)
def test_property_sphere_step_error_is_the_sagitta_of_the_cl_chord(
    radius_mm, tool_radius_mm, sweep_rad, n_points, inside
) -> None:
    surface = Sphere(radius_mm, inside=inside, sweep_rad=sweep_rad)
    path = iso_parametric_path(surface, n_lines=3, n_points=n_points, tool_radius_mm=tool_radius_mm)
    result = step_error_um(path)
    expected = _reference(surface, n_points, tool_radius_mm)
    np.testing.assert_allclose(result.error_um, expected, rtol=0, atol=TOL_UM)
    assert np.all(result.error_um >= 0)


def test_convex_bump_gives_smaller_distance_and_concave_dent_larger() -> None:
    bump = BumpSurface(60.0, 60.0, 10.0, ((0.5, 0.5, 0.25, 0.25, 1.0),))
    dent = BumpSurface(60.0, 60.0, 10.0, ((0.5, 0.5, 0.25, 0.25, -1.0),))
    for surface, convex in ((bump, True), (dent, False)):
        path = iso_parametric_path(surface, n_lines=3, n_points=40)
        result = step_error_um(path)
        middle = 40 + 19  # the segment across the top of the bump (middle line, middle segment)
        assert result.convex[middle] == convex
        assert result.error_um[middle] > 1.0


def test_vectorised_equals_iterative_on_a_paper_surface() -> None:
    path = iso_parametric_path(paper_surface(1))
    exact = step_error_um(path).error_um
    picked = np.random.default_rng(0).choice(path.n_segments, 300, replace=False)
    iterative = step_error_iterative_um(path, segments=picked)
    np.testing.assert_allclose(exact[picked], iterative, rtol=0, atol=TOL_UM)


def test_tighter_tolerance_changes_nothing_above_1e_6_um() -> None:
    path = iso_parametric_path(paper_surface(2), n_lines=20)
    np.testing.assert_allclose(
        step_error_um(path).error_um, step_error_um(path, xtol=1e-10).error_um, atol=TOL_UM
    )


@pytest.mark.parametrize("index", [1, 2, 3])
def test_paper_surfaces_have_the_papers_step_error_range(index: int) -> None:
    paper = load_paper_table("zhang2023_surfaces").set_index("surface").loc[index]
    result = step_error_um(iso_parametric_path(paper_surface(index)))
    assert result.error_um.max() <= paper.step_err_max_um
    assert result.error_um.max() >= 0.9 * paper.step_err_max_um
    assert 0.3 < result.convex.mean() < 0.7  # convex and concave regions both matter


def test_eq8_input_width() -> None:
    k = inner_points_for_hidden_width(28)
    n = 3 * k + 13
    assert 1 <= 28 - math.sqrt(n + 1) <= 10  # eq. 8 with a in [1, 10]
    assert 28 - math.sqrt(n - 3 + 1) > 10  # one point fewer does not fit
    assert k == 104
    with pytest.raises(ValueError, match="hidden"):
        inner_points_for_hidden_width(3)


def test_samples_follow_table_1() -> None:
    path = iso_parametric_path(paper_surface(3), n_lines=4, n_points=10)
    x = step_error_samples(path, 5)
    assert x.shape == (4 * 9, 3 * 5 + 13) and len(sample_columns(5)) == x.shape[1]
    seg = path.segments()
    i = 13
    du = seg["u1"][i] - seg["u0"][i]
    np.testing.assert_allclose(
        x[i, :3], path.surface.point(seg["u0"][i] + du / 6, seg["v"][i]), atol=1e-12
    )
    np.testing.assert_array_equal(x[i, 15:18], seg["cc0"][i])
    np.testing.assert_array_equal(x[i, 24:27], seg["cl1"][i])
    assert np.all(x[:, -1] == 5.0)
    with pytest.raises(ValueError, match="n_inner"):
        step_error_samples(path, 0)


def test_bad_parameters_raise() -> None:
    path = iso_parametric_path(Sphere(20.0), n_lines=2, n_points=5)
    with pytest.raises(ValueError, match="xtol"):
        step_error_um(path, xtol=0.5)
    with pytest.raises(ValueError, match="xatol"):
        step_error_iterative_um(path, xatol=0.0)
    with pytest.raises(ValueError, match="radius_mm"):
        chord_step_error_um(4.0, 5.0, 0.1, inside=True)


def test_extremes_at_segment_ends_equal_the_iterative_method() -> None:
    # near inflections d(u) is monotone on a segment: the extreme is an end, found from the
    # end normals without any Newton step
    path = iso_parametric_path(paper_surface(3))
    result = step_error_um(path)
    seg = path.segments()
    at_end = np.flatnonzero((result.u_critical == seg["u0"]) | (result.u_critical == seg["u1"]))
    assert 20 < len(at_end) < 0.1 * path.n_segments
    iterative = step_error_iterative_um(path, segments=at_end)
    np.testing.assert_allclose(result.error_um[at_end], iterative, rtol=0, atol=TOL_UM)
