"""The Fanuc-like truth calibrated to Lee et al. 2022's conditions: in-position times and the
test piece's run time, never the estimator's error."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from nctwin.chapters import lee2022 as lee
from nctwin.chapters import lee2022_testbed as bed
from nctwin.kernel import fanuc
from nctwin.machine import load_machine
from nctwin.programs import iso10791
from nctwin.report.papers import load_paper_table

MACHINE = load_machine("fanuc_0i_testbed")
SETS = lee.parameter_sets("fanuc_0i_testbed", load_paper_table("lee2022_validation"))
TARGET_S = load_paper_table("lee2022_inposition").inpos_ms.to_numpy() / 1000


@pytest.fixture(scope="module")
def calibrated():
    return bed.calibrated_sets(MACHINE, SETS, TARGET_S)


def test_the_calibrated_servo_gives_the_papers_in_position_times(calibrated):
    truth = calibrated[1][1]
    measured = fanuc.measure_inposition_times(MACHINE, truth)
    assert measured == pytest.approx(TARGET_S, abs=0.0015)
    # X and Y by their width at the profile's gain; Z's width would be under 1 um: its gain
    assert truth.position_gain_per_s[:2] == SETS[1][1].position_gain_per_s[:2]
    assert truth.inposition_width_mm[2] == SETS[1][1].inposition_width_mm[2]
    assert truth.position_gain_per_s[2] < SETS[1][1].position_gain_per_s[2]
    # one servo for both sets; only the time constants differ
    other = calibrated[2][1]
    assert other.inposition_width_mm == truth.inposition_width_mm
    assert other.position_gain_per_s == truth.position_gain_per_s


def test_the_wait_is_the_first_order_decay_to_the_calibrated_width(calibrated):
    # X at Kp = 50 1/s: a wider band is reached sooner, by ln(w1 / w0) / Kp
    truth = calibrated[1][1]
    x, y, z = truth.inposition_width_mm
    wider = dataclasses.replace(truth, inposition_width_mm=(2 * x, y, z))
    t0 = fanuc.measure_inposition_times(MACHINE, truth, axes=(0,))[0]
    t1 = fanuc.measure_inposition_times(MACHINE, wider, axes=(0,))[0]
    assert t0 - t1 == pytest.approx(np.log(2) / 50.0, abs=0.0015)


def test_the_chapters_passes_are_the_count_nearest_the_papers_run_time(calibrated):
    measured_s = float(load_paper_table("lee2022_validation").measured_s[0])
    assert bed.passes_for_run_time(MACHINE, calibrated[1][1], measured_s) == bed.TEST_PIECE_PASSES
    run = fanuc.simulate(iso10791.test_piece(bed.test_piece_params()), MACHINE, calibrated[1][1])
    assert abs(run.cycle_time_s / measured_s - 1) < 0.05


def test_out_of_range_targets_are_refused():
    with pytest.raises(ValueError, match=r"target_s = 0 is out of range"):
        bed.passes_for_run_time(MACHINE, SETS[1][1], 0)
    with pytest.raises(ValueError, match=r"max_passes = 1"):
        bed.passes_for_run_time(MACHINE, SETS[1][1], 2169.1, max_passes=1)
    with pytest.raises(ValueError, match=r"target_s\[0\] = 100.0 is out of range"):
        bed.calibrate_servo(MACHINE, SETS[1][1], (100.0, 0.025, 0.12))
