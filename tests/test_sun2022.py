"""Sun et al. (2022): the features of Table 1 (eq. 5-8) by hand, and eq. 9-10."""

from __future__ import annotations

import math

import numpy as np
import pytest

from nctwin import parse
from nctwin.learn.models import ModelConfig, build
from nctwin.methods.sun2022 import FEATURES as SUN2022_FEATURES
from nctwin.methods.sun2022 import features as sun2022_features


def test_features_by_hand():
    # 3-4-5 triangle legs at 600 mm/min (10 mm/s), then a rapid straight back
    tp = parse("G1 X30 F600\nY40\nG0 X0 Y0")
    f = sun2022_features(tp, rapid_feed_mm_s=500.0)
    assert f.shape == (3, 3, len(SUN2022_FEATURES))
    # eq. 5-6: block 0 takes 3 s, X feed 10 mm/s; block 1: Y feed 10 mm/s
    np.testing.assert_allclose(f[0, :, 4], [10.0, 0.0, 0.0])
    np.testing.assert_allclose(f[1, :, 4], [0.0, 10.0, 0.0])
    # the rapid: 50 mm at 500 mm/s, direction (-0.6, -0.8)
    np.testing.assert_allclose(f[2, :, 4], [-300.0, -400.0, 0.0])
    # eq. 7: block 1's X acceleration (0 - 10) / 4 s; block 0 starts from rest: 10 / 3 s
    assert f[1, 0, 7] == pytest.approx(-2.5)
    assert f[0, 0, 7] == pytest.approx(10.0 / 3.0)
    # eq. 8: a right angle has cosine 0; the end of the program counts as straight on (-1)
    assert f[0, 0, 1] == pytest.approx(0.0, abs=1e-12)
    # at CL_1 = (30, 40): (CL_2 - CL_1) . (CL_0 - CL_1) = (-30, -40) . (0, -40) = 1600 over 50 * 40
    assert f[1, 0, 1] == pytest.approx(0.8)
    assert f[2, 0, 1] == -1.0
    # n-1 and n+1 columns are the neighbours' values, edges repeated
    np.testing.assert_allclose(f[1, :, 3], f[0, :, 4])
    np.testing.assert_allclose(f[1, :, 5], f[2, :, 4])
    np.testing.assert_allclose(f[0, :, 3], f[0, :, 4])


def test_zero_length_blocks_are_refused():
    with pytest.raises(ValueError, match="zero length"):
        sun2022_features(parse("G1 X1 F60\nX1"), 500.0)


def test_mlp_widths_build_the_papers_network():
    model = build(ModelConfig(kind="mlp", n_inputs=9, n_outputs=1, mlp_widths=(5, 10)))
    shapes = [tuple(p.shape) for p in model.parameters()]
    assert shapes == [(5, 9), (5,), (10, 5), (10,), (1, 10), (1,)]
    with pytest.raises(ValueError, match="mlp_widths"):
        ModelConfig(kind="mlp", mlp_widths=(5, 0))


class _Constant:
    """Stands in for a trained network: predicts one feed everywhere."""

    def __init__(self, value: float) -> None:
        self.value = value

    def predict(self, x: np.ndarray) -> np.ndarray:
        return np.full((len(x), 1), self.value)


@pytest.fixture(scope="module")
def triangle_run():
    from nctwin.chapters.sun2022 import run_pocket
    from nctwin.machine import load_profile

    return run_pocket("G21 G91\nG1 X30 F600\nY40\n", 0, load_profile("sun2022_siemens"))


def test_eq9_eq10_by_hand(triangle_run):
    from nctwin.chapters.sun2022 import predict_time, target_time

    run = triangle_run
    # axis feeds (3, 4, 0) give a resultant of 5 mm/s (eq. 9): 70 mm take 14 s (eq. 10)
    t, resultant = predict_time([[_Constant(3.0), _Constant(4.0), _Constant(0.0)]], run)
    np.testing.assert_allclose(resultant, 5.0)
    assert t == pytest.approx(70.0 / 5.0)
    # block averages over a long, simple path: eq. 10 gives the machine's time back closely
    assert target_time(run, "true") == pytest.approx(run.measured_s, rel=0.01)


def test_the_ensemble_averages_the_seeds_times(triangle_run):
    from nctwin.chapters.sun2022 import predict_time

    # 70 mm: seeds predicting (2, 4, 0) and (4, 4, 0) mm/s take 70 / sqrt(20) and 70 / sqrt(32) s;
    # the ensemble takes the mean of the two times
    a = [_Constant(2.0), _Constant(4.0), _Constant(0.0)]
    b = [_Constant(4.0), _Constant(4.0), _Constant(0.0)]
    both = 0.5 * (70 / math.sqrt(20) + 70 / math.sqrt(32))
    assert predict_time([a, b], triangle_run)[0] == pytest.approx(both)
    # seeds that agree on speed but not on direction: (4, 0, 0) and (0, 4, 0) both take 17.5 s,
    # where their mean vector (2, 2, 0) would be 2.83 mm/s, 24.7 s
    c = [_Constant(4.0), _Constant(0.0), _Constant(0.0)]
    d = [_Constant(0.0), _Constant(4.0), _Constant(0.0)]
    assert predict_time([c, d], triangle_run)[0] == pytest.approx(17.5)


def test_time_by_block_length_splits_the_path(triangle_run):
    from nctwin.chapters.sun2022 import time_by_block_length

    # 30 and 40 mm lines are both long blocks; constant feeds (3, 4, 0) give 70 / 5 = 14 s
    table = time_by_block_length({0: triangle_run}, [[_Constant(3.0), _Constant(4.0),
                                                      _Constant(0.0)]])  # fmt: skip
    long, short = table.iloc[0], table.iloc[1]
    assert (long["blocks"], long["count"], short["count"]) == ("long", 2, 0)
    assert long["length_share_pct"] == pytest.approx(100.0)
    assert long["model_s"] == pytest.approx(14.0)
    assert long["machine_s"] == pytest.approx(triangle_run.measured_s, rel=0.01)


def test_models_are_table2():
    from nctwin.chapters.sun2022 import MODELS
    from nctwin.report.papers import load_paper_table

    table2 = load_paper_table("sun2022_table2")
    paper = {
        f"model #{m}": tuple(int(p) for p in str(pockets).split(";"))
        for m, pockets in zip(table2["model"], table2["train_pockets"], strict=True)
    }
    assert paper == MODELS
    assert (table2["validation_pocket"] == 4).all() and (table2["test_pocket"] == 4).all()
