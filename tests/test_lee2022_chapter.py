"""The chapter on Lee et al. 2022: its programs, its truths with one effect on, its tables and
claims, against numbers computed by hand."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from nctwin import parse
from nctwin.chapters import lee2022 as lee
from nctwin.controls import FanucControl
from nctwin.estimate.block_overlap import block_overlap
from nctwin.kernel import fanuc
from nctwin.machine import load_machine, load_profile
from nctwin.methods.lee2022 import check_program
from nctwin.paths import data_dir
from nctwin.recordings import load_recordings
from nctwin.report.papers import load_paper_table

PAPER = load_paper_table("lee2022_validation")
SETS = lee.parameter_sets("fanuc_0i_testbed", PAPER)
MACHINE = load_machine("fanuc_0i_testbed")


def truth_with(effect: str, s: int = 1) -> FanucControl:
    return lee._effect_settings(SETS[s][1], lee.EFFECTS[effect])


@pytest.mark.parametrize("name", list(lee.PROGRAM_FILES))
def test_shipped_programs_are_their_generators_output(name):
    path = data_dir() / "programs" / lee.PROGRAM_FILES[name]
    assert path.read_text(encoding="utf-8") == lee.program_text(name)
    assert lee.load_program(name).allclose(parse(lee.program_text(name)))


def test_unknown_program_and_unmodelled_constructs_are_refused():
    with pytest.raises(ValueError, match="name = 'x' is out of range"):
        lee.load_program("x")
    with pytest.raises(ValueError, match=r"^p\.nc:3: exact-stop mode \(G61/G61\.1\)"):
        check_program(parse("G1 X1 F100\nG61\nG1 X2"), "p.nc")
    with pytest.raises(ValueError, match=r"^p\.nc:2: G64 P blending tolerance"):
        check_program(parse("G64 P0.05\nG1 X1 F100"), "p.nc")


def test_parameter_sets_are_the_papers():
    # each set's (ATR, As, AT) as data/papers/lee2022_validation.csv transcribes them, in ms
    for row in PAPER.itertuples():
        want = (row.atr_ms / 1000, row.as_ms / 1000, row.at_ms / 1000)
        for c in SETS[row.param_set]:
            assert (c.rapid_time_constant_s, c.rapid_bell_s, c.cut_time_constant_s) == want
    # the profile's [control.fanuc] table is the testbed the defaults describe, its
    # [control.accdec] table the estimator's set 1
    assert SETS[1][1] == fanuc.PAPER_SET_1 and SETS[2][1] == fanuc.PAPER_SET_2
    assert SETS[1][0] == load_profile("fanuc_0i_testbed").accdec


def test_the_estimators_model_switches_every_effect_off():
    none = truth_with("none (the estimator's model)")
    assert none.arc_radial_acc_mm_s2 == math.inf and none.block_time_s == 0.0
    assert none.inposition_width_mm == lee._NO_WAIT_MM and none.cut_accdec == "linear"
    assert truth_with("all (the testbed)") == fanuc.PAPER_SET_1
    for effect, changes in lee.EFFECTS.items():
        if not changes:
            continue
        st = truth_with(effect)
        differ = {k for k in changes if getattr(st, k) != getattr(none, k)}
        assert differ == set(changes), effect


def _both(text: str, effect: str) -> tuple[float, float]:
    tp = parse(text)
    truth = fanuc.simulate(tp, MACHINE, truth_with(effect)).cycle_time_s
    model = SETS[1][0]
    return truth, block_overlap(tp, MACHINE, model, inposition_s=(0.0, 0.0, 0.0)).cycle_time_s


def test_arc_clamp_is_what_the_estimator_misses_on_a_lead_arc():
    # half circle of R2 at F6000: the clamp sqrt(200 mm/s^2 * 2 mm) = 20 mm/s
    text = "G1 X0.001 F6000\nG2 X4.001 I2"
    length = 0.001 + 2 * math.pi
    truth, pred = _both(text, "arc clamp")
    assert pred == pytest.approx(0.001 + math.ceil(2 * math.pi / 100 / 0.001) * 0.001 + 0.05)
    # the truth interpolates both blocks as one stream (the 0.001 mm line takes 10 us, not a
    # whole period), and a K-period moving average stretches m periods to m + K - 1 (eq. 3 adds K)
    stream_s = 0.001 / 100 + 2 * math.pi / 20
    assert truth == pytest.approx(math.ceil(stream_s / 0.001) * 0.001 + 0.049)
    truth_off, _ = _both(text, "none (the estimator's model)")
    # without the clamp: the stream's 63 periods + 49, where the estimator rounds the tiny line
    # up to a whole period and adds K: 2 ms more
    assert truth_off == pytest.approx(
        math.ceil((0.001 + 2 * math.pi) / 100 / 0.001) * 0.001 + 0.049
    )
    assert pred - truth_off == pytest.approx(0.002, abs=1e-9)
    assert length / 100 < pred < truth


def test_block_processing_time_limits_short_chords():
    # ten chords of 0.1 mm at F6000: 1 ms each by eq. 2, at least 4 ms each on the truth
    text = "\n".join(f"G1 X{0.1 * (k + 1):.1f} F6000" for k in range(10))
    truth, pred = _both(text, "block-processing time")
    assert pred == pytest.approx(10 * 0.001 + 0.05)
    assert truth == pytest.approx(10 * 0.004 + 0.049)  # m + K - 1 periods, as above


def test_claims_are_reported_not_asserted():
    rows = []
    for prog, err, cam in ((lee.TEST_PIECE, 0.05, -2.0), (lee.FINISHING_3D, -11.0, -40.0)):
        for s in (1, 2):
            for variant, e in (("full", err), ("no_overlap", 5.0), ("no_inposition", err - 1)):
                rows.append({"program": prog, "param_set": s, "variant": variant,
                             "accuracy_pct": 100 - abs(e), "err_pct": e,
                             "cam_err_pct": cam})  # fmt: skip
    claims = {c.id: c for c in lee.claims(pd.DataFrame(rows), 0.002)}
    assert len(claims) == 13
    tp, f3 = f"{lee.TEST_PIECE}_set1", f"{lee.FINISHING_3D}_set2"
    assert claims[f"accuracy_{tp}"].holds and not claims[f"accuracy_{f3}"].holds
    assert claims[f"accuracy_{tp}"].threshold == 99.0  # the paper's "99 % or more"
    assert claims[f"beats_cam_{tp}"].value == pytest.approx(40.0)
    assert claims[f"beats_cam_{f3}"].value == pytest.approx(40.0 / 11.0)
    assert claims[f"beats_cam_{f3}"].holds  # better than CAM: a ratio above 1
    assert claims[f"beats_cam_{tp}"].whose == "paper" and claims[f"beats_cam_{f3}"].whose == "ours"
    assert "inpos_z" in claims[f"accuracy_{tp}"].requires
    assert claims[f"accuracy_{f3}"].requires == ()
    assert claims["prediction_time"].holds and claims["prediction_time"].threshold == 1.0
    assert claims["prediction_time"].value == pytest.approx(0.1)  # 2 ms rounded up to 0.1 s
    assert claims[f"overlap_matters_{tp}"].value == pytest.approx(99.95 - 95.0)


def test_inposition_table_is_beside_the_papers():
    table = lee.inposition_table({1: np.array([0.05, 0.05, 0.06])}, load_paper_table(
        "lee2022_inposition"), MACHINE, SETS)  # fmt: skip
    assert list(table.axis) == ["X", "Y", "Z"]
    np.testing.assert_allclose(table.inpos_ms, [50.0, 50.0, 60.0])
    assert list(table.paper_inpos_ms) == [25, 25, 120]
    own = fanuc.measure_inposition_times(MACHINE, SETS[1][1])
    np.testing.assert_allclose(table.truth_set_inpos_ms, 1000 * own)


def test_out_of_domain_rows_per_group():
    recs = load_recordings()
    few = {k: recs[k] for k in sorted(recs) if k.startswith(("train_00", "test_"))}
    table = lee.out_of_domain_table(few)
    assert set(table.group) == {"train", "test"}
    assert table.programs.sum() + table.not_read.sum() == len(few)
    assert (table.max_abs_err_pct >= table.median_abs_err_pct).all()


def test_conditions_are_the_papers_with_ours_beside():
    from nctwin.chapters.lee2022_conditions import paper_conditions
    from nctwin.machine import load_machine

    machine = load_machine("fanuc_0i_testbed")
    sets = lee.parameter_sets("fanuc_0i_testbed", load_paper_table("lee2022_validation"))

    class Run:  # a truth run of 455 s
        cycle_time_s = 455.0

    inpos = {1: np.array([0.025, 0.030, 0.05]), 2: np.array([0.025, 0.025, 0.12])}
    runs = {(lee.TEST_PIECE, s): Run() for s in sets}
    conds = {c.id: c for c in paper_conditions(machine, sets, inpos, runs)}
    # measured once, with the first set (set 2's array is not read)
    assert conds["inpos_x"].met and conds["inpos_y"].met  # 30 ms: within 20 % of 25
    assert not conds["inpos_z"].met  # 50 ms against 120
    assert "inpos_z_set2" not in conds
    assert conds["test_piece_time_set1"].paper == 2169.1 and not conds["test_piece_time_set1"].met
    assert conds["test_piece_over_30min_set1"].ours == pytest.approx(455 / 60)
    assert all(conds[f"{c}_set{s}"].met for c in ("atr", "as", "at") for s in (1, 2))
    assert conds["rapid_set1"].met and conds["rapid_linear_set1"].met
