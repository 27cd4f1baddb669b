r"""The experiment of Lee et al. (2022): the analytic cycle time with block overlap and
in-position compensation against a simulated Fanuc-like control, as tables.

The "measured" machine is :mod:`nctwin.kernel.accdec` (profile ``fanuc_0i_testbed``) with the
paper's two parameter sets (:func:`parameter_set_machines`); the estimator under test is the
paper's calculator, :func:`nctwin.estimate.block_overlap.block_overlap`, with its in-position
times measured on the kernel as the paper measured them
(:func:`nctwin.kernel.accdec.measure_inposition_times`).

* :func:`inposition_table`: the measured in-position times beside the paper's;
* :func:`accuracy_table`: for each program and parameter set, the kernel's cycle time, the
  prediction with block overlap and in-position compensation and its two ablations, CAM's;
* :func:`claims`: the chapter's claims, from the accuracy table;
* :func:`plot_overlap_profiles` and :func:`plot_block_errors`: the figures (they only draw).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from ..estimate import estimate
from ..estimate.block_overlap import block_overlap
from ..gcode import parse
from ..kernel.accdec import AccDecRun, InPositionMeasurement, simulate
from ..machine import MachineProfile
from ..report.tables import Claim, accuracy_pct, error_pct
from ..toolpath import Toolpath

__all__ = [
    "TEST_PIECE",
    "VARIANTS",
    "accuracy_table",
    "claims",
    "inposition_table",
    "parameter_set_machines",
    "plot_block_errors",
    "plot_overlap_profiles",
    "speed_profile",
]

#: Name of the ISO 10791-7 test-piece program (the paper's program) in the tables.
TEST_PIECE = "iso10791_7_test_piece"
#: The estimator's variants: the paper's method and its two ablations (keyword arguments of
#: :func:`~nctwin.estimate.block_overlap.block_overlap`).
VARIANTS = {
    "full": {},
    "no_overlap": {"overlap": False},
    "no_inposition": {"inposition": False},
}


def parameter_set_machines(base: MachineProfile, paper: pd.DataFrame) -> dict[int, MachineProfile]:
    """The testbed with each of the paper's parameter sets (time constants
    :math:`A_{TR}`, :math:`A_s`, :math:`A_T`).

    Parameters
    ----------
    base : MachineProfile
        The testbed (``fanuc_0i_testbed``).
    paper : pandas.DataFrame
        The paper table ``lee2022_validation``: one row per parameter set with ``param_set``,
        ``atr_ms``, ``as_ms`` and ``at_ms``.

    Returns
    -------
    dict
        ``param_set -> MachineProfile`` named ``fanuc_0i_testbed_set<param_set>``, in the order
        of the table's rows.
    """
    return {
        int(row.param_set): dataclasses.replace(
            base,
            name=f"fanuc_0i_testbed_set{row.param_set}",
            rapid_time_constant_s=row.atr_ms / 1000,
            rapid_bell_s=row.as_ms / 1000,
            cut_time_constant_s=row.at_ms / 1000,
        )
        for row in paper.itertuples()
    }


def inposition_table(
    inpos: dict[int, InPositionMeasurement], paper_inpos: pd.DataFrame
) -> pd.DataFrame:
    """The measured in-position times per parameter set and axis, beside the paper's.

    Parameters
    ----------
    inpos : dict
        ``param_set -> InPositionMeasurement`` (``mean_s`` of shape (3,), ``samples_s`` of shape
        (3, repeats)).
    paper_inpos : pandas.DataFrame
        The paper table ``lee2022_inposition`` (``axis``, ``inpos_ms``).

    Returns
    -------
    pandas.DataFrame
        One row per parameter set and axis (X, Y, Z): ``param_set, axis, inpos_ms, min_ms,
        max_ms, paper_inpos_ms``.
    """
    paper_ms = dict(zip(paper_inpos["axis"], paper_inpos["inpos_ms"], strict=True))
    return pd.DataFrame(
        [
            {
                "param_set": s,
                "axis": axis,
                "inpos_ms": 1000 * meas.mean_s[i],
                "min_ms": 1000 * meas.samples_s[i].min(),
                "max_ms": 1000 * meas.samples_s[i].max(),
                "paper_inpos_ms": paper_ms[axis],
            }
            for s, meas in inpos.items()
            for i, axis in enumerate("XYZ")
        ]
    )


def accuracy_table(
    programs: dict[str, Toolpath],
    machines: dict[int, MachineProfile],
    inpos: dict[int, InPositionMeasurement],
    paper: pd.DataFrame,
) -> tuple[dict[tuple[str, int], AccDecRun], pd.DataFrame]:
    """Measured against predicted: every program on every parameter set, with every variant.

    Parameters
    ----------
    programs : dict
        ``name -> Toolpath`` of N blocks each.
    machines : dict
        ``param_set -> MachineProfile`` (:func:`parameter_set_machines`).
    inpos : dict
        ``param_set -> InPositionMeasurement``; its ``mean_s`` (shape (3,)) is the estimator's
        in-position compensation per axis.
    paper : pandas.DataFrame
        The paper table ``lee2022_validation`` (``param_set``, ``measured_s``, ``predicted_s``,
        ``accuracy_pct``); beside the test piece's ``full`` rows only.

    Returns
    -------
    runs : dict
        ``(program, param_set) -> AccDecRun``, the kernel's runs.
    accuracy : pandas.DataFrame
        One row per program, parameter set and variant (:data:`VARIANTS`): ``program,
        param_set, variant, measured_s, predicted_s, accuracy_pct, cam_s, cam_err_pct,
        paper_measured_s, paper_predicted_s, paper_accuracy_pct``.
    """
    runs, rows = {}, []
    for prog, tp in programs.items():
        for s, m in machines.items():
            runs[prog, s] = simulate(tp, m)
            measured = runs[prog, s].cycle_time_s
            cam = estimate(tp, m, "cam").cycle_time_s
            ref = paper.set_index("param_set").loc[s]
            for variant, kw in VARIANTS.items():
                pred = block_overlap(tp, m, inposition_s=inpos[s].mean_s, **kw).cycle_time_s
                is_paper = prog == TEST_PIECE and variant == "full"
                rows.append(
                    {
                        "program": prog,
                        "param_set": s,
                        "variant": variant,
                        "measured_s": measured,
                        "predicted_s": pred,
                        "accuracy_pct": accuracy_pct(pred, measured),
                        "cam_s": cam,
                        "cam_err_pct": error_pct(cam, measured),
                        "paper_measured_s": ref.measured_s if is_paper else np.nan,
                        "paper_predicted_s": ref.predicted_s if is_paper else np.nan,
                        "paper_accuracy_pct": ref.accuracy_pct if is_paper else np.nan,
                    }
                )
    return runs, pd.DataFrame(rows)


def claims(accuracy: pd.DataFrame) -> list[Claim]:
    """The chapter's claims (Lee et al. 2022, Sec. 3-4), from :func:`accuracy_table`.

    Per program and parameter set: accuracy at least 99 %, block overlap worth more than one
    percentage point, and (on the test piece only: the other program has three rapids, whose
    compensation is within the rounding bias) in-position compensation improving the accuracy;
    then the test piece running over 30 minutes.

    Parameters
    ----------
    accuracy : pandas.DataFrame
        :func:`accuracy_table`'s rows (columns ``program, param_set, variant, accuracy_pct,
        measured_s``).

    Returns
    -------
    list of Claim
    """
    full = accuracy[accuracy.variant == "full"].set_index(["program", "param_set"])
    no_bo = accuracy[accuracy.variant == "no_overlap"].set_index(["program", "param_set"])
    no_ip = accuracy[accuracy.variant == "no_inposition"].set_index(["program", "param_set"])
    claims = []
    for prog, s in full.index:
        tag = f"{prog}_set{s}"
        claims.append(
            Claim(
                f"accuracy_{tag}",
                f"Accuracy >= 99 % on {prog}, parameter set {s} (Lee et al. 2022, Sec. 3-4)",
                full.loc[(prog, s), "accuracy_pct"],
                ">=",
                99.0,
            )
        )
        claims.append(
            Claim(
                f"overlap_matters_{tag}",
                f"Removing block overlap costs more than 1 percentage point of accuracy on {prog}, "
                f"set {s}",
                full.loc[(prog, s), "accuracy_pct"] - no_bo.loc[(prog, s), "accuracy_pct"],
                ">",
                1.0,
            )
        )
        if prog != TEST_PIECE:
            continue  # three rapids: the compensation is within the rounding bias
        claims.append(
            Claim(
                f"inposition_helps_{tag}",
                f"In-position compensation improves accuracy on {prog}, set {s}",
                full.loc[(prog, s), "accuracy_pct"] - no_ip.loc[(prog, s), "accuracy_pct"],
                ">",
                0.0,
            )
        )
    claims.append(
        Claim(
            "test_piece_over_30_min",
            "The test-piece program runs over 30 minutes on the testbed (paper: > 30 min, 2169 s)",
            full.loc[(TEST_PIECE, 1), "measured_s"] / 60,
            ">",
            30.0,
        )
    )
    return claims


# ------------------------------------------------------------------------------------------------
# Figures


def speed_profile(
    text: str, machine: MachineProfile, start_mm: tuple[float, float, float] = (0.0, 0.0, 0.0)
) -> tuple[np.ndarray, np.ndarray]:
    """Path speed of a program run on the kernel.

    Parameters
    ----------
    text : str
        A G-code program.
    machine : MachineProfile
    start_mm : tuple of float
        Start position of the tool.

    Returns
    -------
    t_s : ndarray, shape (n,)
        Sample times.
    speed_mm_min : ndarray, shape (n,)
        Path speed in mm/min.
    """
    motion = simulate(parse(text, start_mm=start_mm), machine).motion
    return motion.t_s, motion.speed_mm_s * 60


def plot_overlap_profiles(machines: dict[int, MachineProfile]):
    """Block overlap (the paper's Fig. 6-7): three 20 mm cutting blocks with set 1 and five
    0.87 mm chords with set 2, each once overlapped and once with an exact stop (a zero-length
    dwell) between blocks; only draws.

    Parameters
    ----------
    machines : dict
        ``param_set -> MachineProfile`` with sets 1 and 2.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    lines = ["G1 X20 F1000", "G1 X40", "G1 X60"]
    angles = np.radians([5, 10, 15, 20, 25])
    chords = [f"G1 X{10 * np.cos(a):.4f} Y{10 * np.sin(a):.4f} F1000" for a in angles]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.5))
    for ax, blocks, m, title in (
        (axes[0], lines, machines[1], "normal blocks, $A_T$ = 50 ms"),
        (axes[1], chords, machines[2], "short blocks, $A_T$ = 100 ms"),
    ):
        start = (0.0, 0.0, 0.0) if blocks is lines else (10.0, 0.0, 0.0)
        t, v = speed_profile("\n".join(blocks), m, start)
        t2, v2 = speed_profile("\nG4 X0\n".join(blocks), m, start)
        ax.plot(t2, v2, label="no overlap (exact stop)", color="tab:gray", ls="--")
        ax.plot(t, v, label="block overlap", color="tab:blue")
        ax.set(xlabel="time (s)", ylabel="path speed (mm/min)", title=title)
        ax.legend(loc="lower center")
    fig.tight_layout()
    return fig


def plot_block_errors(
    runs: dict[tuple[str, int], AccDecRun],
    programs: dict[str, Toolpath],
    machines: dict[int, MachineProfile],
    inpos: dict[int, InPositionMeasurement],
    program: str = TEST_PIECE,
):
    """Predicted minus measured time of each block of one program, per parameter set; only
    draws.

    Parameters
    ----------
    runs : dict
        ``(program, param_set) -> AccDecRun`` (:func:`accuracy_table`; ``block_times_s`` of shape
        (N,)).
    programs : dict
        ``name -> Toolpath``; ``programs[program]`` has N blocks.
    machines : dict
        ``param_set -> MachineProfile``.
    inpos : dict
        ``param_set -> InPositionMeasurement`` (the estimator's compensation).
    program : str
        The program shown.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(10, 5), sharex=True)
    tp = programs[program]
    rapid = tp.kind == 0
    for ax, (s, m) in zip(axes, machines.items(), strict=True):
        pred = block_overlap(tp, m, inposition_s=inpos[s].mean_s).block_times_s
        err_ms = 1000 * (pred - runs[program, s].block_times_s)
        idx = np.arange(len(tp))
        ax.plot(idx[~rapid], err_ms[~rapid], ".", ms=2, label="cutting blocks and dwells")
        ax.plot(idx[rapid], err_ms[rapid], "x", ms=4, color="tab:red", label="rapids")
        ax.set(ylabel="predicted - measured (ms)", title=f"parameter set {s}")
        ax.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("block")
    fig.tight_layout()
    return fig
