"""Free-form surfaces and iso-parametric tool paths (Zhang et al. 2023, Sec. "Sample
construction")."""

from __future__ import annotations

import numpy as np
import pytest

from nctwin.physics.surfaces import (
    PAPER_BUMPS,
    BumpSurface,
    Cylinder,
    Sphere,
    iso_parametric_path,
    paper_surface,
)
from nctwin.report.papers import load_paper_table

PAPER = load_paper_table("zhang2023_surfaces").set_index("surface")


@pytest.mark.parametrize("index", [1, 2, 3])
def test_bounding_box_is_the_papers(index: int) -> None:
    surface = paper_surface(index)
    box = PAPER.loc[index]
    u, v = np.meshgrid(np.linspace(0, 1, 601), np.linspace(0, 1, 601))
    p = surface.point(u, v)
    assert p[..., 0].min() == 0.0 and p[..., 0].max() == pytest.approx(box.bbox_x_mm, abs=1e-12)
    assert p[..., 1].min() == 0.0 and p[..., 1].max() == pytest.approx(box.bbox_y_mm, abs=1e-12)
    z = p[..., 2]
    # the fitted extremes bound every grid point and the grid comes close to them
    assert z.min() >= -1e-9 and z.max() <= box.bbox_z_mm + 1e-9
    assert z.max() - z.min() == pytest.approx(box.bbox_z_mm, abs=0.01)


@pytest.mark.parametrize("index", [1, 2, 3])
def test_normals_are_unit_upward_and_normal_to_the_surface(index: int) -> None:
    surface = paper_surface(index)
    rng = np.random.default_rng(index)
    u, v = rng.uniform(0.01, 0.99, 50), rng.uniform(0.01, 0.99, 50)
    p, n = surface.point_normal(u, v)
    np.testing.assert_allclose(np.linalg.norm(n, axis=-1), 1.0, atol=1e-14)
    assert np.all(n[:, 2] > 0)
    h = 1e-6
    tu = (surface.point(u + h, v) - surface.point(u - h, v)) / (2 * h)
    tv = (surface.point(u, v + h) - surface.point(u, v - h)) / (2 * h)
    np.testing.assert_allclose(np.einsum("ij,ij->i", tu, n), 0.0, atol=1e-6)
    np.testing.assert_allclose(np.einsum("ij,ij->i", tv, n), 0.0, atol=1e-6)
    np.testing.assert_allclose(p, surface.point(u, v), atol=0)


@pytest.mark.parametrize(
    "surface",
    [paper_surface(2), Sphere(20.0), Sphere(20.0, inside=True), Cylinder(15.0)],
    ids=["bumps", "sphere", "sphere-inside", "cylinder"],
)
def test_curve_jet_is_the_point_and_its_u_derivatives(surface) -> None:
    rng = np.random.default_rng(0)
    u, v = rng.uniform(0.01, 0.99, 40), rng.random(40)
    jet = surface.curve_jet(v)
    c, c_u, c_uu = jet(u)
    np.testing.assert_allclose(c, surface.point(u, v), rtol=0, atol=1e-12)
    h = 1e-5  # central differences: truncation error ~ h^2 times the next derivative / 6
    (cp, cp_u, _), (cm, cm_u, _) = jet(u + h), jet(u - h)
    scale = np.abs(c_u).max()
    np.testing.assert_allclose(c_u, (cp - cm) / (2 * h), rtol=0, atol=1e-6 * scale)
    np.testing.assert_allclose(c_uu, (cp_u - cm_u) / (2 * h), rtol=0, atol=1e-5 * scale)


def test_papers_path_has_19800_segments_and_cl_is_r_along_the_normal() -> None:
    path = iso_parametric_path(paper_surface(1))
    assert path.cc_mm.shape == path.cl_mm.shape == (200, 100, 3)
    assert path.n_segments == 19_800
    offset = path.cl_mm - path.cc_mm
    np.testing.assert_allclose(np.linalg.norm(offset, axis=-1), 5.0, atol=1e-12)
    np.testing.assert_allclose(offset / 5.0, path.normal, atol=1e-15)
    seg = path.segments()
    assert seg["cc0"].shape == (19_800, 3)
    # segment 99 is the first of line 2: it starts at the first CC point of that line
    np.testing.assert_array_equal(seg["cc0"][99], path.cc_mm[1, 0])
    np.testing.assert_array_equal(seg["cl1"][98], path.cl_mm[0, 99])


def test_cylinder_and_sphere_points_lie_on_them() -> None:
    u, v = np.meshgrid(np.linspace(0, 1, 7), np.linspace(0, 1, 5))
    p, n = Sphere(30.0).point_normal(u, v)
    np.testing.assert_allclose(np.linalg.norm(p, axis=-1), 30.0, atol=1e-12)
    np.testing.assert_allclose(n, p / 30.0, atol=1e-15)
    p, n = Cylinder(20.0, inside=True).point_normal(u, v)
    np.testing.assert_allclose(np.hypot(p[..., 0], p[..., 2]), 20.0, atol=1e-12)
    np.testing.assert_allclose(n[..., 1], 0.0)
    assert np.all(np.einsum("...i,...i->...", n, p) < 0)  # inside: normals point to the axis


def test_bad_parameters_raise_value_error_naming_them() -> None:
    with pytest.raises(ValueError, match="size_z_mm"):
        BumpSurface(10.0, 10.0, 0.0, ((0.5, 0.5, 0.1, 0.1, 1.0),))
    with pytest.raises(ValueError, match="bumps"):
        BumpSurface(10.0, 10.0, 1.0, ((0.5, 0.5, 0.1, 1.0),))
    with pytest.raises(ValueError, match="sigma_x"):
        BumpSurface(10.0, 10.0, 1.0, ((0.5, 0.5, -0.1, 0.1, 1.0),))
    with pytest.raises(ValueError, match="n_points"):
        iso_parametric_path(Sphere(10.0), n_points=1)
    with pytest.raises(ValueError, match="tool_radius_mm"):
        iso_parametric_path(Sphere(10.0), tool_radius_mm=-5.0)
    with pytest.raises(ValueError, match="index"):
        paper_surface(4)
    assert sorted(PAPER_BUMPS) == [1, 2, 3]
