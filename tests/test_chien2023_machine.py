import dataclasses

import numpy as np
import pandas as pd
import pytest

from nctwin.chapters import chien2023_machine as cm
from nctwin.machine import load_profile

BASE = load_profile("paper1_sim")


def test_with_kinematics_sets_the_filters_and_scales_z_by_the_base_ratio():
    acc, jerk = BASE.machine.axis_max_acceleration_mm_s2, BASE.machine.axis_max_jerk_mm_s3
    p = cm.with_kinematics(BASE, cm.Kinematics(0.1, 0.03, 1000.0, 4e4))
    assert (p.fir.t1_s, p.fir.t2_s) == (0.1, 0.03)
    assert p.machine.axis_max_acceleration_mm_s2 == pytest.approx(
        (1000.0, 1000.0, 1000.0 * acc[2] / acc[0])
    )
    assert p.machine.axis_max_jerk_mm_s3 == pytest.approx((4e4, 4e4, 4e4 * jerk[2] / jerk[0]))
    # everything else is the base's: the published feeds, period and tolerance
    assert dataclasses.replace(p.fir, t1_s=BASE.fir.t1_s, t2_s=BASE.fir.t2_s) == BASE.fir
    assert p.machine.max_feed_mm_s == BASE.machine.max_feed_mm_s


def test_calibrate_machine_picks_the_smallest_largest_deviation(monkeypatch):
    # candidate 0 misses one row by 4 points, candidate 1 every row by 3: candidate 1 wins
    def fake_rows(profile, shares, iterations):
        dev = [4.0, 0.0, 0.0] if profile.fir.t1_s == 0.1 else [3.0, -3.0, 3.0]
        return pd.DataFrame({"toolpath": ["I", "II", "pocketing"], "deviation_pts": dev})

    monkeypatch.setattr(cm, "machine_rows", fake_rows)
    grid = [cm.Kinematics(0.1, 0.02, 2000.0, 1e5), cm.Kinematics(0.2, 0.02, 2000.0, 1e5)]
    best, rows = cm.calibrate_machine(BASE, grid, [0.3], 1)
    assert best == grid[1]
    assert list(rows.t1_s) == [0.1] * 3 + [0.2] * 3


@pytest.mark.slow
def test_machine_rows_solves_each_path_and_scores_against_the_paper():
    rows = cm.machine_rows(BASE, [0.25, 0.3], iterations=1)
    assert list(rows.toolpath) == ["pocketing"] * 4 + ["I"] * 4 + ["II"] * 4
    np.testing.assert_allclose(rows.deviation_pts, rows.cam_err_pct - rows.paper_cam_err_pct)
    assert set(rows.setting[4:]) <= {0.25, 0.3}
    # on a real machine CAM, which ignores corners, is always short
    assert (rows.cam_err_pct > 0).all()
