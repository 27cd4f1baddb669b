r"""The experiment of Lee et al. (2022): the analytic cycle time with block overlap and
in-position compensation, tested against a Fanuc-like control that is not its own formula.

The "measured" machine is :mod:`nctwin.kernel.fanuc` (the ``[control.fanuc]`` table of profile
``fanuc_0i_testbed`` with the paper's two parameter sets, :func:`parameter_sets`): a
time-domain control with acc/dec after interpolation, a block-processing time, an arc clamp,
bell-shaped rapids and servo loops whose in-position waits come out of the simulation, its servo
and the test piece's passes calibrated to the paper's conditions
(:mod:`nctwin.chapters.lee2022_testbed`). It shares no code and no equation with the estimator
under test, :func:`nctwin.estimate.block_overlap.block_overlap` (the paper's eq. 1-16,
:mod:`nctwin.methods.lee2022`): it carries the period remainder from block to block where eq. 2
rounds each block, and filters rapids after interpolation where eq. 9-12 price short ones as
triangles.
:mod:`nctwin.kernel.accdec`, the ideal machine the estimator was derived for, gives only the
sanity rows (:func:`ideal_table`).

* :func:`load_program`, :func:`program_text`, :func:`program_statistics_table`: the two shipped
  programs (the ISO 10791-7-style test piece and the 3D finishing program) and their statistics
  beside real CAM finishing output;
* :func:`inposition_table`: in-position times measured on the truth beside the paper's;
* :func:`truth_runs`: the programs on the truth, before the estimator runs (the paper's
  conditions beside ours: :mod:`nctwin.chapters.lee2022_conditions`);
* :func:`accuracy_table`: measured, predicted (and its ablations), CAM, the paper's numbers;
* :func:`truth_effects_table`: the estimator against truths with one effect switched on;
* :func:`out_of_domain_table`: the estimator on the shipped LinuxCNC recordings;
* :func:`claims`: the chapter's claims;
* :func:`plot_overlap_profiles` and :func:`plot_block_errors`: the figures (they only draw).
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path

import numpy as np
import pandas as pd

from ..controls import AccDecControl, FanucControl
from ..estimate.block_overlap import block_overlap
from ..estimate.cam import cam
from ..gcode import GCodeError, parse, parse_file
from ..identify import identified_block_overlap
from ..kernel import accdec, fanuc
from ..kernel.fanuc import FanucRun
from ..machine import Machine, load_profile
from ..methods.lee2022 import check_program
from ..metrics import accuracy_pct, error_pct
from ..paths import data_dir
from ..programs.finishing3d import finishing3d_program, program_statistics, real_cam_text
from ..programs.iso10791 import test_piece_program
from ..recordings import RecordedProgram, public_program_text
from ..report.claims import Claim
from ..report.papers import load_paper_table
from ..toolpath import MotionKind, Toolpath
from .lee2022_testbed import test_piece_params
from .your_program import ProgramResult, block_feeds, block_summary, program_times, run_program

__all__ = [
    "EFFECTS",
    "FINISHING_3D",
    "PREDICTION_RESOLUTION_S",
    "PROGRAM_FILES",
    "REAL_CAM_PROGRAMS",
    "REQUIRES",
    "TEST_PIECE",
    "VARIANTS",
    "accuracy_table",
    "claims",
    "ideal_table",
    "inposition_table",
    "load_program",
    "measure_inposition",
    "out_of_domain_table",
    "parameter_sets",
    "plot_block_errors",
    "plot_overlap_profiles",
    "prediction_time_s",
    "program_statistics_table",
    "program_text",
    "truth_effects_table",
    "truth_runs",
    "your_program",
]

#: The programs' names in the tables.
TEST_PIECE = "iso10791_7_test_piece"
FINISHING_3D = "finishing3d"
#: Each program's file in ``data/programs/``.
PROGRAM_FILES = {TEST_PIECE: "lee2022_test_piece.nc", FINISHING_3D: "finishing3d_seed0.nc"}
#: Seed of the shipped 3D finishing program.
FINISHING_SEED = 0
#: Real CAM 3D finishing programs (``data/programs/public/``) whose chord lengths the 3D
#: program follows (:mod:`nctwin.programs.finishing3d`).
REAL_CAM_PROGRAMS = ("LHchips4.ngc", "camotics_bear.nc")
#: The conditions each of the paper's claims on the test piece is tested under
#: (:func:`nctwin.chapters.lee2022_conditions.paper_conditions`): the in-position rule (the
#: slowest moving axis's time after a rapid) matters only where the axes' times differ as the
#: paper's do, and the test piece must run as long as the paper's.
REQUIRES = {
    "accuracy": ("inpos_x", "inpos_y", "inpos_z", "test_piece_time_set{s}"),
    "beats_cam": ("inpos_x", "inpos_y", "inpos_z", "test_piece_time_set{s}"),
    "prediction_time": ("test_piece_time_set{s}",),
}
#: The estimator's variants: the paper's method and its two ablations (keyword arguments of
#: :func:`~nctwin.estimate.block_overlap.block_overlap`).
VARIANTS = {
    "full": {},
    "no_overlap": {"overlap": False},
    "no_inposition": {"inposition": False},
}
#: In-position width that never makes the control wait (the truth without in-position checks).
_NO_WAIT_MM = (10.0, 10.0, 10.0)
#: The truth's effects, each as the settings that switch it on over the estimator's own model
#: (linear acc/dec, no arc clamp, no block-processing time, no in-position wait). Values are
#: the testbed's (:class:`~nctwin.controls.FanucControl` defaults) or, for the
#: alternatives the testbed does not use, the other type Fanuc offers.
EFFECTS = {
    "none (the estimator's model)": {},
    "in-position check": {"inposition_width_mm": None},
    "in-position, second-order servo": {"inposition_width_mm": None, "servo": "second_order"},
    "block-processing time": {"block_time_s": None},
    "arc clamp": {"arc_radial_acc_mm_s2": None},
    "bell cutting acc/dec": {"cut_accdec": "bell"},
    "exponential cutting acc/dec": {"cut_accdec": "exponential"},
    "rapid overlap": {"rapid_overlap": True},
    "all (the testbed)": None,
}


# ------------------------------------------------------------------------------------------------
# Programs and machines


def program_text(name: str) -> str:
    """A chapter program regenerated by its generator (the shipped file must equal it).

    Parameters
    ----------
    name : {TEST_PIECE, FINISHING_3D}
    """
    if name == TEST_PIECE:
        return test_piece_program(test_piece_params())
    if name == FINISHING_3D:
        return finishing3d_program(FINISHING_SEED)
    raise ValueError(f"name = {name!r} is out of range: allowed {', '.join(PROGRAM_FILES)}")


def load_program(name: str) -> Toolpath:
    """A chapter program read from its shipped file in ``data/programs/``.

    Raises
    ------
    ValueError
        For an unknown name, or ``"<file>:<line>: <reason>"`` for a construct the estimator
        cannot model (:func:`nctwin.methods.lee2022.check_program`).
    """
    if name not in PROGRAM_FILES:
        raise ValueError(f"name = {name!r} is out of range: allowed {', '.join(PROGRAM_FILES)}")
    path = data_dir() / "programs" / PROGRAM_FILES[name]
    tp = parse_file(path)
    check_program(tp, str(path))
    return tp


def your_program(
    path, machine: Machine, sets: dict[int, tuple[AccDecControl, FanucControl]],
    inpos: dict[int, np.ndarray], param_set: int = 1,
) -> ProgramResult:  # fmt: skip
    """Lee's block-overlap estimate of a reader's program beside the Fanuc-like truth's time
    for it and CAM, with the parameter set ``param_set`` (its time constants for both).

    Parameters
    ----------
    path : str or path-like
        A G-code file; a construct the estimator cannot model
        (:func:`nctwin.methods.lee2022.check_program`) or the truth cannot run is the reason.
    machine, sets, inpos
        As for :func:`accuracy_table`.
    param_set : int
        Which of ``sets``.
    """
    model, truth = sets[param_set]

    def method(text: str, source: str) -> ProgramResult:
        tp = parse(text, source=source)
        check_program(tp, source)
        est = block_overlap(tp, machine, model, inposition_s=inpos[param_set])
        run = fanuc.simulate(tp, machine, truth)
        cam_est = cam(tp, machine)
        times = program_times(
            ("Fanuc-like truth", run.cycle_time_s),
            {"block overlap": est.cycle_time_s, "CAM": cam_est.cycle_time_s},
        )
        feeds = block_feeds(tp.lengths_mm, {"true_mm_s": run.block_times_s,
                                            "block overlap_mm_s": est.block_times_s,
                                            "CAM_mm_s": cam_est.block_times_s})  # fmt: skip
        note = (f"parameter set {param_set}; {block_summary(tp)}",)
        return ProgramResult(Path(source).name, times, feeds, note)

    return run_program(path, method)


def program_statistics_table(texts: dict[str, str]) -> pd.DataFrame:
    """Size and chord lengths of the chapter's programs beside the real CAM finishing programs.

    Parameters
    ----------
    texts : dict
        ``name -> G-code text`` of the chapter's programs.

    Returns
    -------
    pandas.DataFrame
        One row per program (ours, then :data:`REAL_CAM_PROGRAMS`): ``program``, ``kind``
        (``"chapter"`` or ``"real CAM output"``) and the columns of
        :func:`nctwin.programs.finishing3d.program_statistics` (the real programs read with
        :func:`~nctwin.programs.finishing3d.real_cam_text`, which restores ``LHchips4.ngc``'s
        feed words).
    """
    public = data_dir() / "programs" / "public"
    rows = [{"program": n, "kind": "chapter", **program_statistics(t)} for n, t in texts.items()]
    rows += [
        {"program": n, "kind": "real CAM output", **program_statistics(real_cam_text(public / n))}
        for n in REAL_CAM_PROGRAMS
    ]
    return pd.DataFrame(rows)


def parameter_sets(
    profile: str, paper: pd.DataFrame
) -> dict[int, tuple[AccDecControl, FanucControl]]:
    """The testbed's controls with each of the paper's parameter sets (:math:`A_{TR}`,
    :math:`A_s`, :math:`A_T`): the control the estimator reads and the truth's.

    Both run on the testbed's :class:`~nctwin.machine.Machine`
    (:func:`nctwin.machine.load_machine` of ``profile``), which no set changes.

    Parameters
    ----------
    profile : str
        The testbed's machine profile (``"fanuc_0i_testbed"``): its ``[control.accdec]`` table
        is the estimator's control, its ``[control.fanuc]`` table the truth's settings.
    paper : pandas.DataFrame
        The paper table ``lee2022_validation`` (``param_set``, ``atr_ms``, ``as_ms``,
        ``at_ms``).

    Returns
    -------
    dict
        ``param_set -> (AccDecControl, FanucControl)`` in the order of the table's rows.
    """
    testbed = load_profile(profile)
    model, truth = testbed.control("accdec"), testbed.control("fanuc")
    out = {}
    for row in paper.itertuples():
        consts = {
            "rapid_time_constant_s": row.atr_ms / 1000,
            "rapid_bell_s": row.as_ms / 1000,
            "cut_time_constant_s": row.at_ms / 1000,
        }
        out[int(row.param_set)] = (
            dataclasses.replace(model, **consts),
            dataclasses.replace(truth, **consts),
        )
    return out


def measure_inposition(
    machine: Machine, sets: dict[int, tuple[AccDecControl, FanucControl]]
) -> dict[int, np.ndarray]:
    """The in-position times of X, Y, Z (s) the estimator uses with every set: measured once on
    the truth with the first set, as the paper did (Sec. 3: one measurement, used for both
    sets; :func:`nctwin.kernel.fanuc.measure_inposition_times`: single-axis rapids from rest)."""
    once = fanuc.measure_inposition_times(machine, next(iter(sets.values()))[1])
    return {s: once for s in sets}


def inposition_table(
    inpos: dict[int, np.ndarray],
    paper_inpos: pd.DataFrame,
    machine: Machine,
    sets: dict[int, tuple[AccDecControl, FanucControl]],
) -> pd.DataFrame:
    """The in-position times the estimator uses per set and axis, beside the paper's and beside
    what the same measurement gives on the truth with that set's time constants.

    Parameters
    ----------
    inpos : dict
        ``param_set -> ndarray`` of shape (3,), s (:func:`measure_inposition`).
    paper_inpos : pandas.DataFrame
        The paper table ``lee2022_inposition`` (``axis``, ``inpos_ms``).
    machine, sets
        As for :func:`truth_runs`.

    Returns
    -------
    pandas.DataFrame
        ``param_set, axis, inpos_ms, paper_inpos_ms, truth_set_inpos_ms``.
    """
    paper_ms = dict(zip(paper_inpos["axis"], paper_inpos["inpos_ms"], strict=True))
    rows = []
    for s, t in inpos.items():
        own = fanuc.measure_inposition_times(machine, sets[s][1])
        rows += [{"param_set": s, "axis": a, "inpos_ms": 1000 * t[i], "paper_inpos_ms": paper_ms[a],
                  "truth_set_inpos_ms": 1000 * own[i]} for i, a in enumerate("XYZ")]  # fmt: skip
    return pd.DataFrame(rows)


def truth_runs(
    programs: dict[str, Toolpath],
    machine: Machine,
    sets: dict[int, tuple[AccDecControl, FanucControl]],
) -> dict[tuple[str, int], FanucRun]:
    """Every program run on the truth with every parameter set: ``(program, param_set) ->
    FanucRun``."""
    return {(p, s): fanuc.simulate(tp, machine, st) for p, tp in programs.items()
            for s, (_, st) in sets.items()}  # fmt: skip


#: Resolution (s) to which the prediction's wall time is rounded up for its claim, so that
#: ``claims.json`` is the same on every run of the same machine.
PREDICTION_RESOLUTION_S = 0.1


def prediction_time_s(
    tp: Toolpath, machine: Machine, model: AccDecControl, inposition_s: np.ndarray
) -> float:
    """Wall time (s) of one block-overlap estimate of ``tp``: read once, it varies run to run."""
    t0 = time.perf_counter()
    block_overlap(tp, machine, model, inposition_s=inposition_s)
    return time.perf_counter() - t0


# ------------------------------------------------------------------------------------------------
# Tables


def accuracy_table(
    programs: dict[str, Toolpath],
    runs: dict[tuple[str, int], FanucRun],
    machine: Machine,
    sets: dict[int, tuple[AccDecControl, FanucControl]],
    inpos: dict[int, np.ndarray],
    paper: pd.DataFrame,
) -> pd.DataFrame:
    """Measured (the Fanuc-like truth) against predicted: every program, set and variant.

    Parameters
    ----------
    programs : dict
        ``name -> Toolpath`` of N blocks each.
    runs : dict
        :func:`truth_runs` of ``programs``.
    machine : Machine
        The testbed, for the estimator and CAM.
    sets : dict
        :func:`parameter_sets`.
    inpos : dict
        ``param_set -> ndarray`` (3,): the estimator's in-position compensation per axis.
    paper : pandas.DataFrame
        The paper table ``lee2022_validation``; beside the test piece's ``full`` rows only.

    Returns
    -------
    pandas.DataFrame
        One row per program, set and variant (:data:`VARIANTS`): ``program, param_set,
        variant, measured_s, predicted_s, accuracy_pct, err_pct`` (signed), ``cam_s,
        cam_err_pct`` (signed), ``paper_measured_s, paper_predicted_s, paper_accuracy_pct``.
    """
    ref = paper.set_index("param_set")
    rows = []
    for prog, tp in programs.items():
        for s, (model, _) in sets.items():
            measured = runs[prog, s].cycle_time_s
            cam_s = cam(tp, machine).cycle_time_s
            for variant, kw in VARIANTS.items():
                pred = block_overlap(tp, machine, model, inposition_s=inpos[s], **kw).cycle_time_s
                beside = prog == TEST_PIECE and variant == "full"
                rows.append(
                    {
                        "program": prog,
                        "param_set": s,
                        "variant": variant,
                        "measured_s": measured,
                        "predicted_s": pred,
                        "accuracy_pct": accuracy_pct(pred, measured),
                        "err_pct": error_pct(pred, measured, signed=True),
                        "cam_s": cam_s,
                        "cam_err_pct": error_pct(cam_s, measured, signed=True),
                        "paper_measured_s": ref.loc[s, "measured_s"] if beside else np.nan,
                        "paper_predicted_s": ref.loc[s, "predicted_s"] if beside else np.nan,
                        "paper_accuracy_pct": ref.loc[s, "accuracy_pct"] if beside else np.nan,
                    }
                )
    return pd.DataFrame(rows)


def ideal_table(
    programs: dict[str, Toolpath],
    machine: Machine,
    sets: dict[int, tuple[AccDecControl, FanucControl]],
) -> pd.DataFrame:
    """The sanity rows: the estimator on the ideal machine it was derived for
    (:mod:`nctwin.kernel.accdec`: ``machine`` with each set's acc/dec control), with in-position
    times measured on that machine.

    Returns
    -------
    pandas.DataFrame
        ``program, param_set, measured_s, predicted_s, accuracy_pct, err_pct``.
    """
    rows = []
    for s, (model, _) in sets.items():
        inpos = accdec.measure_inposition_times(machine, model).mean_s
        for prog, tp in programs.items():
            measured = accdec.simulate(tp, machine, model).cycle_time_s
            pred = block_overlap(tp, machine, model, inposition_s=inpos).cycle_time_s
            rows.append(
                {"program": prog, "param_set": s, "measured_s": measured, "predicted_s": pred,
                 "accuracy_pct": accuracy_pct(pred, measured),
                 "err_pct": error_pct(pred, measured, signed=True)}
            )  # fmt: skip
    return pd.DataFrame(rows)


def _effect_settings(testbed: FanucControl, changes: dict | None) -> FanucControl:
    """The truth with one effect on: the estimator's model plus ``changes`` (None values take
    the testbed's value; ``changes`` None is the testbed itself)."""
    if changes is None:
        return testbed
    model = dataclasses.replace(
        testbed, arc_radial_acc_mm_s2=math.inf, block_time_s=0.0, inposition_width_mm=_NO_WAIT_MM
    )
    on = {k: getattr(testbed, k) if v is None else v for k, v in changes.items()}
    return dataclasses.replace(model, **on)


def truth_effects_table(
    programs: dict[str, Toolpath],
    machine: Machine,
    sets: dict[int, tuple[AccDecControl, FanucControl]],
) -> pd.DataFrame:
    """The estimator against truths that have only one effect switched on (:data:`EFFECTS`).

    For each truth the in-position times are measured on that truth (as the paper measured
    them on its testbed) and given to the estimator.

    Returns
    -------
    pandas.DataFrame
        One row per effect, program and set: ``effect, program, param_set, measured_s,
        predicted_s, accuracy_pct, err_pct`` (signed), ``inpos_x_ms, inpos_y_ms, inpos_z_ms``.
    """
    rows = []
    for effect, changes in EFFECTS.items():
        for s, (model, testbed) in sets.items():
            st = _effect_settings(testbed, changes)
            inpos = fanuc.measure_inposition_times(machine, st)
            for prog, tp in programs.items():
                measured = fanuc.simulate(tp, machine, st).cycle_time_s
                pred = block_overlap(tp, machine, model, inposition_s=inpos).cycle_time_s
                rows.append(
                    {"effect": effect, "program": prog, "param_set": s, "measured_s": measured,
                     "predicted_s": pred, "accuracy_pct": accuracy_pct(pred, measured),
                     "err_pct": error_pct(pred, measured, signed=True),
                     **{f"inpos_{a}_ms": 1000 * inpos[i] for i, a in enumerate("xyz")}}
                )  # fmt: skip
    return pd.DataFrame(rows)


def out_of_domain_table(recordings: dict[str, RecordedProgram]) -> pd.DataFrame:
    """The estimator on LinuxCNC's recordings, its time constants identified from the machine
    (:func:`nctwin.identify.identified_block_overlap`, at LinuxCNC's servo period, the
    profile's ``[control.planner]`` ``period_s``), per group of recordings.

    Parameters
    ----------
    recordings : dict
        :func:`nctwin.recordings.load_recordings`; the group is the name's first word
        (``train``, ``test``, ``broad``, ``cam``, ``lang``, ``public``, ``sample``).

    Returns
    -------
    pandas.DataFrame
        One row per group: ``group, programs, not_read`` (public programs whose text is absent
        or that the native reader refuses), ``median_abs_err_pct, max_abs_err_pct,
        median_err_pct`` (signed), ``cam_median_abs_err_pct``.
    """
    groups: dict[str, dict[str, list]] = {}
    for name, rec in recordings.items():
        g = groups.setdefault(name.split("_")[0], {"err": [], "cam": [], "not_read": []})
        text = public_program_text(rec)
        profile = load_profile(rec.machine)
        try:
            tp = parse(text, tool_table=profile.tool_table) if text is not None else None
        except GCodeError:
            tp = None
        if tp is None:
            g["not_read"].append(name)
            continue
        machine = profile.machine
        lee = identified_block_overlap(tp, machine, profile.control("planner").period_s)
        pred = block_overlap(tp, machine, lee).cycle_time_s
        g["err"].append(error_pct(pred, rec.cycle_time_s, signed=True))
        g["cam"].append(error_pct(cam(tp, machine).cycle_time_s, rec.cycle_time_s))
    return pd.DataFrame(
        [
            {"group": k, "programs": len(g["err"]), "not_read": len(g["not_read"]),
             "median_abs_err_pct": float(np.median(np.abs(g["err"]))),
             "max_abs_err_pct": float(np.max(np.abs(g["err"]))),
             "median_err_pct": float(np.median(g["err"])),
             "cam_median_abs_err_pct": float(np.median(g["cam"]))}
            for k, g in groups.items()
            if g["err"]
        ]
    )  # fmt: skip


def _paper_bar(quantity: str) -> tuple[str, float, str]:
    """A claim's relation, bar and citation from ``data/papers/lee2022_summary.csv``."""
    row = load_paper_table("lee2022_summary").set_index("quantity").loc[quantity]
    return str(row.relation), float(row.value), f"{row.paper}, {row.page_or_section}"


def claims(accuracy: pd.DataFrame, prediction_s: float) -> list[Claim]:
    """The paper's claims at its own bars (``data/papers/lee2022_summary.csv``) on the test
    piece, and the same checks, nctwin's own, on the 3D program, from :func:`accuracy_table`.

    Per program and parameter set: the accuracy at the paper's bar (``cycle_time_accuracy``);
    ``beats_cam``, the estimator's error smaller than CAM's (the ratio of CAM's to the
    estimator's above the paper's ``cam_to_estimate_error_ratio``, 1); ``overlap_matters``
    (nctwin's), removing block overlap costs more than one percentage point of accuracy. Once:
    ``prediction_time``, the estimate of the test piece within the paper's time
    (``prediction_time``). The paper's claims require the conditions of :data:`REQUIRES` for
    their set (:func:`nctwin.chapters.lee2022_conditions.paper_conditions`).

    Parameters
    ----------
    accuracy : pandas.DataFrame
        :func:`accuracy_table`'s rows (``program, param_set, variant, accuracy_pct, err_pct,
        cam_err_pct``).
    prediction_s : float
        :func:`prediction_time_s` of the test piece with set 1 (s); the claim's value is it
        rounded up to :data:`PREDICTION_RESOLUTION_S`.

    Returns
    -------
    list of Claim
    """
    full = accuracy[accuracy.variant == "full"].set_index(["program", "param_set"])
    no_bo = accuracy[accuracy.variant == "no_overlap"].set_index(["program", "param_set"])
    acc_op, acc_bar, acc_cite = _paper_bar("cycle_time_accuracy")
    cam_op, cam_bar, cam_cite = _paper_bar("cam_to_estimate_error_ratio")
    out = []
    for prog, s in full.index:
        row, tag = full.loc[(prog, s)], f"{prog}_set{s}"
        paper = prog == TEST_PIECE  # Lee et al. claim nothing for 3D programs

        def cited(text: str, cite: str, kind: str, _paper=paper, _s=s) -> dict:
            req = tuple(c.format(s=_s) for c in REQUIRES[kind]) if _paper else ()
            return {"text": f"{text} ({cite})" if _paper else text, "requires": req,
                    "whose": "paper" if _paper else "ours"}  # fmt: skip

        out += [
            Claim(f"accuracy_{tag}", value=row.accuracy_pct, op=acc_op, threshold=acc_bar,
                  **cited(f"Accuracy {acc_op} {acc_bar:g} % on {prog}, parameter set {s}",
                          acc_cite, "accuracy")),
            Claim(f"beats_cam_{tag}", value=abs(row.cam_err_pct) / max(abs(row.err_pct), 1e-12),
                  op=cam_op, threshold=cam_bar,
                  **cited(f"The estimate is more accurate than CAM's length over feed on {prog}, "
                          f"set {s} (CAM's error over the estimator's)", cam_cite, "beats_cam")),
            Claim(f"overlap_matters_{tag}", f"Removing block overlap costs more than 1 percentage "
                  f"point of accuracy on {prog}, set {s}",
                  row.accuracy_pct - no_bo.loc[(prog, s), "accuracy_pct"], ">", 1.0, whose="ours"),
        ]  # fmt: skip
    op, bar, cite = _paper_bar("prediction_time")
    res = PREDICTION_RESOLUTION_S
    out.append(Claim("prediction_time", f"The estimate of the test piece takes {op} {bar:g} s "
                     f"(wall time read once, rounded up to {res:g} s; {cite})",
                     math.ceil(prediction_s / res) * res, op, bar,
                     requires=tuple(c.format(s=1)
                                    for c in REQUIRES["prediction_time"])))  # fmt: skip
    return out


# ------------------------------------------------------------------------------------------------
# Figures


def _speed(
    text: str, machine: Machine, truth: FanucControl, start_mm: tuple[float, ...]
) -> tuple[np.ndarray, np.ndarray]:
    """Measured path speed (mm/min) over time of a program run on the truth."""
    motion = fanuc.simulate(parse(text, start_mm=start_mm), machine, truth).motion
    return motion.t_s, motion.speed_mm_s * 60


def plot_overlap_profiles(machine: Machine, sets: dict[int, tuple[AccDecControl, FanucControl]]):
    """Block overlap on the truth (the paper's Fig. 6-7): three 20 mm cutting blocks with set 1
    and five 0.87 mm chords with set 2, each once overlapped and once with an exact stop (a
    zero-length dwell) between blocks; only draws.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    lines = ["G1 X20 F1000", "G1 X40", "G1 X60"]
    angles = np.radians([5, 10, 15, 20, 25])
    chords = [f"G1 X{10 * np.cos(a):.4f} Y{10 * np.sin(a):.4f} F1000" for a in angles]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.5))
    for ax, blocks, s, title in (
        (axes[0], lines, 1, "normal blocks, $A_T$ = 50 ms"),
        (axes[1], chords, 2, "short blocks, $A_T$ = 100 ms"),
    ):
        start = (0.0, 0.0, 0.0) if blocks is lines else (10.0, 0.0, 0.0)
        t, v = _speed("\n".join(blocks), machine, sets[s][1], start)
        t2, v2 = _speed("\nG4 X0\n".join(blocks), machine, sets[s][1], start)
        ax.plot(t2, v2, label="no overlap (exact stop)", color="tab:gray", ls="--")
        ax.plot(t, v, label="block overlap", color="tab:blue")
        ax.set(xlabel="time (s)", ylabel="path speed (mm/min)", title=title)
        ax.legend(loc="lower center")
    fig.tight_layout()
    return fig


def plot_block_errors(
    runs: dict[tuple[str, int], FanucRun],
    tp: Toolpath,
    machine: Machine,
    sets: dict[int, tuple[AccDecControl, FanucControl]],
    inpos: dict[int, np.ndarray],
    program: str,
):
    """Cumulative predicted minus measured time along one program, per parameter set, split by
    kind of block (chords, arcs, rapids); only draws.

    Parameters
    ----------
    runs : dict
        ``(program, param_set) -> FanucRun`` (:func:`accuracy_table`).
    tp : Toolpath
        The program, N blocks.
    machine, sets, inpos
        As for :func:`accuracy_table`.
    program : str
        The program's name in ``runs``.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(10, 3.5))
    kinds = {
        "lines (G1)": tp.kind == MotionKind.LINEAR,
        "arcs (G2/G3)": tp.is_arc,
        "rapids (G0) and dwells": np.isin(tp.kind, (MotionKind.RAPID, MotionKind.DWELL)),
    }
    idx = np.arange(len(tp))
    for (s, (model, _)), ls in zip(sets.items(), ("-", "--"), strict=True):
        err = block_overlap(tp, machine, model, inposition_s=inpos[s]).block_times_s
        err = err - runs[program, s].block_times_s
        for (label, mask), c in zip(kinds.items(), ("tab:blue", "tab:orange", "tab:red"),
                                    strict=True):  # fmt: skip
            ax.plot(idx, np.cumsum(np.where(mask, err, 0.0)), ls, color=c,
                    label=f"{label}, set {s}")  # fmt: skip
    ax.set(xlabel="block", ylabel="cumulative predicted - measured (s)", title=program)
    ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    return fig
