"""The Denkena chapter's "Your process": what the bench refuses (one line per bad value, the
feed range the run allows), and a process end to end with a tiny network, scored by hand; the
force turns with the feed direction."""

from __future__ import annotations

import re

import numpy as np
import pytest

from nctwin.chapters import denkena2020 as dk
from nctwin.chapters import denkena2020_yours as dy
from nctwin.methods import denkena2020 as fm
from nctwin.physics import drives

MACHINE = drives.FeedDriveMachine()
DURATION_S = 4.0
CENTRE_MM = (150.0, 150.0, 100.0)
TRAVEL_MM = np.array([[20.0, 280.0]] * 3)
GROOVE = {"kind": "groove", "feed_direction": "+x", "ae_mm": 10, "ap_mm": 1,
          "vf_mm_min": 800, "n_rpm": 5000}  # fmt: skip


def make(spec, travel_mm: np.ndarray = TRAVEL_MM) -> dk.Process:
    return dy.make_process(spec, MACHINE, duration_s=DURATION_S, centre_mm=CENTRE_MM,
                           travel_mm=travel_mm, index=0)  # fmt: skip


def refused(spec, travel_mm: np.ndarray = TRAVEL_MM) -> list[str]:
    with pytest.raises(ValueError) as info:
        make(spec, travel_mm)
    return str(info.value).splitlines()


def test_the_string_form_is_the_dict_form() -> None:
    assert dy.process_fields("groove, +x, 10, 1, 800, 5000") == {
        k: float(v) if k.endswith(("_mm", "_min", "_rpm")) else v for k, v in GROOVE.items()
    }
    p = make("groove,+x,10,1,800,5000")
    assert p == make(GROOVE) and not p.semi_stable and p.test


def test_every_bad_value_is_one_line() -> None:
    lines = refused("slot,+x,0,-1,800,1e6")
    assert len(lines) == 4
    assert lines[0] == "kind = 'slot': allowed side, groove, pocket, ramp"
    assert lines[1].startswith("ae_mm = 0.0 is out of range: allowed (0, 10]")  # no cut
    assert lines[2].startswith("ap_mm = -1.0 is out of range: allowed (0, 20]")
    # the teeth must pass below half the 5 kHz servo rate: 60 * 5000 / (2 * 4) 1/min
    assert lines[3] == "n_rpm = 1000000.0 is out of range: allowed (0, 37500]"
    assert refused("pocket,+x,5,2,800,4500") == ["feed_direction = '+x': allowed for pocket ccw"]
    assert refused("groove,+x,5,1,800,5000") == [
        "ae_mm = 5.0: allowed 10 for a groove (the tool's diameter)"
    ]
    assert refused("side,+x,10,1,800,5000")[0].startswith("ae_mm = 10.0 is out of range: "
                                                          "allowed (0, 10)")  # fmt: skip
    assert len(refused({"kind": "side", "speed": 3})) == 6  # five missing, one unknown
    assert refused("groove,+x,ten,1,800,5000") == ["ae_mm = 'ten': allowed a number"]
    assert "6 values separated by commas" in refused("groove,+x,10")[0]


def _feed_range(lines: list[str]) -> tuple[int, int]:
    (line,) = lines
    lo, hi = re.search(r"vf_mm_min = .* allowed \[(\d+), (\d+)\]", line).groups()
    return int(lo), int(hi)


def test_the_feed_range_is_where_the_run_cuts_and_the_path_fits() -> None:
    lo, hi = _feed_range(refused({**GROOVE, "vf_mm_min": 20000}))
    assert _feed_range(refused({**GROOVE, "vf_mm_min": 10})) == (lo, hi)
    for vf in (lo, hi):  # the bounds themselves are allowed, a step beyond is not
        make({**GROOVE, "vf_mm_min": vf})
    refused({**GROOVE, "vf_mm_min": lo - 1})
    refused({**GROOVE, "vf_mm_min": hi + 1})
    # a straight path's length is proportional to the feed: half the travel, half the feed
    half = np.array([[85.0, 215.0]] * 3)
    assert _feed_range(refused({**GROOVE, "vf_mm_min": 20000}, half))[1] == pytest.approx(
        hi / 2, abs=1
    )
    # centred on CENTRE_MM in X and Y, at its height
    p = make(GROOVE)
    length = 2 * (CENTRE_MM[0] - p.start_mm[0])
    assert p.start_mm[1:] == CENTRE_MM[1:] and length > 0


def test_a_refused_process_says_why_under_its_heading(capsys) -> None:
    result = dy.ProcessResult("slot,+x,0,1,800,5000", reason="kind = 'slot': allowed ...")
    dy.show_process(result)
    assert capsys.readouterr().out.splitlines()[-1] == "not run: kind = 'slot': allowed ..."


@pytest.fixture(scope="module")
def chapter(tmp_path_factory):
    """A tiny chapter: three training processes of 4 s, one network per axis trained for two
    epochs, and the model of the drives' own parameters (friction at its steady state)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("NCTWIN_CACHE", str(tmp_path_factory.mktemp("cache")))
        axes = []
        for a in MACHINE.axes:
            grid = np.arange(20.0, 280.5, 0.5)
            friction = fm.StribeckParams(a.coulomb_n, a.breakaway_n, a.stribeck_mm_s,
                                         a.viscous_n_s_mm)  # fmt: skip
            axes.append(fm.AxisModel(a.km_n_a, a.restoring_n_mm, a.rest_point_mm, grid,
                                     drives.cogging_n(grid, a), friction))  # fmt: skip
        model = fm.ForceModel(tuple(axes), np.array([a.own_mass_kg for a in MACHINE.axes]))
        train = [dk.Process(i, k, d, ae, 1.0, 800.0, 5000.0, CENTRE_MM, False, 0.0, 0.0, False)
                 for i, (k, d, ae) in enumerate([("groove", "+x", 10.0), ("side", "+y", 5.0),
                                                 ("groove", "-x+y", 10.0)])]  # fmt: skip
        rec = dk.run_processes(train, MACHINE, duration_s=DURATION_S, seed=0, n_jobs=1)
        targets = fm.target_forces(rec.force_n, MACHINE.record_rate_hz)
        nets, scaling = dk.train_lstms(rec, targets, [0], max_epochs=2, n_jobs=1)

        def run(spec) -> dy.ProcessResult:
            return dy.your_process(spec, nets, scaling, model, MACHINE, rec,
                                   duration_s=DURATION_S, seed=0)  # fmt: skip

        yield run


def test_a_process_end_to_end_scored_by_hand(chapter) -> None:
    r = chapter({**GROOVE, "n_rpm": 4000})
    assert r.reason is None and r.axes == "XY"
    assert list(r.table["axis"]) == ["X", "Y"]
    assert r.measured_n.shape == r.model_n.shape == r.lstm_n.shape == (len(r.t_s), 2)
    cut = r.cutting
    for j, row in r.table.iterrows():
        f = r.measured_n[cut, j]
        assert row.max_abs_force_n == pytest.approx(np.abs(f).max())
        for name, pred in (("lstm", r.lstm_n), ("model", r.model_n)):
            rmse = np.sqrt(np.mean((pred[cut, j] - f) ** 2))
            assert row[f"{name}_cutting_rmse_n"] == pytest.approx(rmse)
    # no force on the workpiece while the tool is in the air (noise only)
    assert np.abs(r.measured_n[~cut]).max() < 0.05 * r.table.max_abs_force_n.max()
    assert r.name.startswith("groove milling +x")
    assert any("n_rpm = 4000 (trained 5000 to 5000)" in n for n in r.notes)
    refused = chapter({**GROOVE, "kind": "slot"})
    assert refused.reason.startswith("kind = 'slot'") and refused.table.empty
    assert refused.name == "slot,+x,10,1,800,5000"


def test_the_force_turns_with_the_feed_direction(chapter) -> None:
    """The workpiece force is the tool's, turned by the feed angle: a +y groove's (Fx, Fy) is a
    +x groove's (-Fy, Fx), up to the dynamometer's noise (the same cut, the same noise seed)."""
    along_x = chapter(GROOVE)
    along_y = chapter({**GROOVE, "feed_direction": "+y"})
    peak = np.abs(along_x.measured_n).max()
    assert peak > 10.0
    turned = np.stack([-along_x.measured_n[:, 1], along_x.measured_n[:, 0]], axis=1)
    assert np.abs(along_y.measured_n - turned).max() < 0.05 * peak
    assert along_y.table.max_abs_force_n.tolist() == pytest.approx(
        along_x.table.max_abs_force_n.tolist()[::-1], rel=0.05
    )
