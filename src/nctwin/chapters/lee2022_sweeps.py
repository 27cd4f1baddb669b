r"""How much of the estimator's verdict on the 3D program the truth's assumed settings decide.

Two settings of the Fanuc-like truth (:class:`~nctwin.controls.FanucControl`) are not the
paper's: the arc clamp (``arc_radial_acc_mm_s2``, the radial acceleration that limits the feed
on an arc to :math:`\sqrt{a_r R}`) and the block-processing time (``block_time_s``, the least
time a block lasts). Both bite only where a program has small arcs or short blocks at a high
feed, as a 3D finishing program does. :func:`sweep_table` varies each over a range, one at a
time with the other at the testbed's value, and reads the estimator's accuracy against each
truth; :func:`feed_variants` gives the 3D program at each cutting feed the real CAM programs it
follows use (:data:`nctwin.chapters.lee2022.REAL_CAM_PROGRAMS`), since the feed decides whether
either setting bites at all.

* :func:`feed_variants`: the 3D program's text at its own feed and at the other real feed;
* :func:`sweep_table`: measured and predicted per program and setting;
* :func:`plot_sweeps`: the figure (it only draws).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd

from ..checks import check_range
from ..controls import AccDecControl, FanucControl
from ..estimate.block_overlap import block_overlap
from ..kernel import fanuc
from ..machine import Machine
from ..metrics import accuracy_pct, error_pct
from ..paths import data_dir
from ..programs.finishing3d import (
    FinishingParams,
    finishing3d_program,
    program_statistics,
    real_cam_text,
)
from ..toolpath import Toolpath

__all__ = [
    "ARC_CLAMPS_MM_S2",
    "BLOCK_TIMES_S",
    "feed_variants",
    "plot_sweeps",
    "real_cam_feeds",
    "sweep_table",
]

#: Arc clamps swept (mm/s^2); ``inf`` is no clamp. The testbed's is 200.
ARC_CLAMPS_MM_S2 = (50.0, 100.0, 200.0, 400.0, 800.0, math.inf)
#: Block-processing times swept (s); 0 is no limit. The testbed's is 0.004.
BLOCK_TIMES_S = (0.0, 0.001, 0.002, 0.004, 0.008)


def real_cam_feeds(names: tuple[str, ...]) -> dict[str, float]:
    """The cutting feed (mm/min) that covers the most cutting length in each real CAM program.

    Parameters
    ----------
    names : tuple of str
        Files in ``data/programs/public/``, read with
        :func:`~nctwin.programs.finishing3d.real_cam_text`.

    Returns
    -------
    dict
        ``name -> feed_main_mm_min`` of :func:`~nctwin.programs.finishing3d.program_statistics`.
    """
    public = data_dir() / "programs" / "public"
    return {n: program_statistics(real_cam_text(public / n))["feed_main_mm_min"] for n in names}


def feed_variants(name: str, seed: int, feeds_mm_min: dict[str, float]) -> dict[str, str]:
    """The 3D program at its own feed and at every other feed of ``feeds_mm_min``.

    Parameters
    ----------
    name : str
        The program's name in the tables (its own feed keeps it).
    seed : int
        Seed of :func:`~nctwin.programs.finishing3d.finishing3d_program`.
    feeds_mm_min : dict
        ``real program -> feed`` (:func:`real_cam_feeds`). A feed other than the generator's
        default becomes a variant named ``f"{name}_F{feed:g}"`` whose passes, lead arcs, links
        and steep chords all run at that feed (one feed, as a program with a single F word).

    Returns
    -------
    dict
        ``name -> G-code text``, the program at its own feed first.
    """
    own = FinishingParams()
    out = {name: finishing3d_program(seed)}
    for feed in sorted(set(feeds_mm_min.values())):
        if feed != own.feed_mm_min:
            params = dataclasses.replace(own, feed_mm_min=feed, steep_feed_mm_min=feed)
            out[f"{name}_F{feed:g}"] = finishing3d_program(seed, params)
    return out


def sweep_table(
    programs: dict[str, Toolpath],
    machine: Machine,
    model: AccDecControl,
    truth: FanucControl,
    inposition_s: np.ndarray,
    arc_clamps_mm_s2: tuple[float, ...] = ARC_CLAMPS_MM_S2,
    block_times_s: tuple[float, ...] = BLOCK_TIMES_S,
) -> pd.DataFrame:
    """The estimator against truths whose arc clamp or block-processing time is varied.

    Each setting is varied alone, the other kept at ``truth``'s value; every other setting of
    the truth (time constants, acc/dec, servo, in-position width) is ``truth``'s. The estimate
    does not depend on either setting, so it is computed once per program, with the in-position
    times ``inposition_s`` (the chapter's, measured once on the testbed).

    Parameters
    ----------
    programs : dict
        ``name -> Toolpath`` of N blocks each.
    machine : Machine
        The testbed.
    model, truth : AccDecControl, FanucControl
        One parameter set: the estimator's control and the truth's settings.
    inposition_s : ndarray, shape (3,)
        The estimator's in-position time per axis X, Y, Z (s).
    arc_clamps_mm_s2 : tuple of float
        Arc clamps to run (mm/s^2), each in (0, inf]; ``inf`` is no clamp.
    block_times_s : tuple of float
        Block-processing times to run (s), each in [0, 1]; 0 is no limit.

    Returns
    -------
    pandas.DataFrame
        One row per program and value: ``program``, ``varied`` (``"arc clamp"`` or
        ``"block time"``), ``arc_radial_acc_mm_s2``, ``block_time_ms``, ``testbed`` (True where
        both settings are the testbed's), ``measured_s``, ``predicted_s``, ``accuracy_pct``,
        ``err_pct`` (signed: negative, the estimate is too short).

    Raises
    ------
    ValueError
        For a value out of its range.
    """
    for v in arc_clamps_mm_s2:
        check_range("arc_clamps_mm_s2", v, 0.0, math.inf, low_open=True)
    for v in block_times_s:
        check_range("block_times_s", v, 0.0, 1.0)
    runs = [("arc clamp", {"arc_radial_acc_mm_s2": float(a)}) for a in arc_clamps_mm_s2]
    runs += [("block time", {"block_time_s": float(b)}) for b in block_times_s]
    rows = []
    for prog, tp in programs.items():
        pred = block_overlap(tp, machine, model, inposition_s=inposition_s).cycle_time_s
        for varied, change in runs:
            st = dataclasses.replace(truth, **change)
            measured = fanuc.simulate(tp, machine, st).cycle_time_s
            rows.append(
                {
                    "program": prog,
                    "varied": varied,
                    "arc_radial_acc_mm_s2": st.arc_radial_acc_mm_s2,
                    "block_time_ms": 1000 * st.block_time_s,
                    "testbed": st == truth,
                    "measured_s": measured,
                    "predicted_s": pred,
                    "accuracy_pct": accuracy_pct(pred, measured),
                    "err_pct": error_pct(pred, measured, signed=True),
                }
            )
    return pd.DataFrame(rows)


def plot_sweeps(table: pd.DataFrame, bar_pct: float):
    """Accuracy against the arc clamp (left) and the block-processing time (right), one line
    per program, the testbed's values marked; only draws.

    Parameters
    ----------
    table : pandas.DataFrame
        :func:`sweep_table`.
    bar_pct : float
        The paper's accuracy bar (%), drawn as a horizontal line.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 3.5), sharey=True)
    arc = table[table.varied == "arc clamp"]
    finite = arc.arc_radial_acc_mm_s2[np.isfinite(arc.arc_radial_acc_mm_s2)]
    at_inf = 2 * finite.max() if len(finite) else 1.0  # where "no clamp" is drawn
    for ax, varied, col in ((axes[0], "arc clamp", "arc_radial_acc_mm_s2"),
                            (axes[1], "block time", "block_time_ms")):  # fmt: skip
        part = table[table.varied == varied]
        for prog, rows in part.groupby("program", sort=False):
            x = rows[col].replace(math.inf, at_inf)
            line = ax.plot(x, rows.accuracy_pct, "o-", label=prog)[0]
            ax.plot(x[rows.testbed], rows.accuracy_pct[rows.testbed], "s", ms=10, mfc="none",
                    color=line.get_color())  # fmt: skip
        ax.axhline(bar_pct, color="tab:gray", ls="--", label=f"the paper's bar, {bar_pct:g} %")
    axes[0].set_xscale("log")
    ticks = [*sorted(finite.unique()), at_inf]
    axes[0].set_xticks(ticks, [f"{t:g}" for t in ticks[:-1]] + ["none"])
    axes[0].minorticks_off()
    axes[0].set(xlabel="arc clamp, allowed radial acceleration (mm/s²)",
                ylabel="accuracy of the estimate (%)")  # fmt: skip
    axes[1].set(xlabel="block-processing time (ms)")
    axes[1].legend(fontsize=8, title="squares: the testbed's value", title_fontsize=8)
    fig.tight_layout()
    return fig
