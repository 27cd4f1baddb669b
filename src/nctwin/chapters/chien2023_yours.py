"""Chien et al.'s BiLSTM on a reader's program (the chapter's "Your program" section).

The BiLSTM reads G-lines: the planar G1 moves of a contour (:func:`cutting_blocks
<nctwin.chapters.chien2023.cutting_blocks>`, as for the chapter's own programs). A part
program holds several contours, joined by rapids, plunges and arcs the method does not read, so
the program's G-lines are cut into *chains* of contiguous planar G1 moves, and each chain is
run on the FIR kernel from rest to rest (the truth) and predicted as a program of its own; the
times are the chains' sums. The moves between the chains are left out of every time.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from .. import gcode
from ..learn.train import Trained
from ..machine import Profile
from ..methods import chien2023 as chien
from ..toolpath import Toolpath
from .chien2023 import ProgramRun, cutting_blocks, predict_run, run_toolpath
from .your_program import ProgramResult, domain_notes, program_times, run_program

__all__ = ["chains", "your_program"]


def chains(tp: Toolpath) -> list[Toolpath]:
    """``tp`` cut where a block does not start at its predecessor's end: the contiguous runs of
    blocks, in order."""
    if len(tp) == 0:
        return []
    jump = np.any(tp.start_mm[1:] != tp.end_mm[:-1], axis=1)
    bounds = np.concatenate([[0], np.flatnonzero(jump) + 1, [len(tp)]])
    return [tp.take(np.arange(a, b)) for a, b in itertools.pairwise(bounds)]


def your_program(
    path, models: Trained | Sequence[Trained], profile: Profile, train_runs: Sequence[ProgramRun]
) -> ProgramResult:
    """The BiLSTM on a reader's program, beside the FIR kernel's time for it (the truth) and CAM.

    Parameters
    ----------
    path : str or path-like
        A G-code file.
    models : Trained or sequence of Trained
        The chapter's network or ensemble (see :func:`predict_run
        <nctwin.chapters.chien2023.predict_run>`), never retrained here.
    profile : Profile
        The machine and ``[control.fir]`` the networks were trained on.
    train_runs : sequence of ProgramRun
        Their training programs, for where the program leaves the training data.

    Returns
    -------
    ProgramResult
        Times summed over the program's chains (the module docstring); the average feed per
        G-line, measured and predicted, over the chains in order.
    """

    def method(text: str, source: str) -> ProgramResult:
        tp = gcode.parse(text, source=source)
        parts = chains(cutting_blocks(tp))
        if not parts:
            raise ValueError(f"{source}: no planar G1 move, the G-lines the BiLSTM reads")
        runs = [run_toolpath(part, profile) for part in parts]
        predicted = [predict_run(models, run) for run in runs]
        kept = sum(len(p) for p in parts)
        x_train = np.concatenate([r.features for r in train_runs])
        notes = (
            f"{kept} planar G1 moves of the program's {len(tp)} blocks are the G-lines read, in "
            f"{len(parts)} chains of contiguous moves, each run from rest to rest; the moves "
            "between them (rapids, plunges, arcs) are left out of every time.",
            *domain_notes(np.concatenate([r.features for r in runs]), x_train, chien.FEATURES),
        )
        times = program_times(
            ("FIR kernel", sum(r.measured_s for r in runs)),
            {"BiLSTM": sum(p[2] for p in predicted), "CAM": sum(r.cam_s for r in runs)},
        )
        feeds = pd.DataFrame({
            "line": np.arange(1, kept + 1),
            "true_mm_s": np.concatenate([r.targets[:, 0] for r in runs]),
            "BiLSTM_mm_s": np.concatenate([p[0] for p in predicted]),
        })  # fmt: skip
        return ProgramResult(Path(source).name, times, feeds, notes)

    return run_program(path, method)
