r"""A reader's own program through a chapter: the paper's method beside the chapter's truth and
CAM.

Every cycle-time chapter takes a ``program`` parameter (a path to a G-code file; None, the
default, is the shipped example :func:`example_program`). The chapter runs as before and its last
cell calls the chapter's ``your_program`` function on it, which returns a :class:`ProgramResult`,
and :func:`show_program` displays it: the cycle times and their errors against the truth in a
table, and the average feed per G-line, true and predicted, along the program in a figure. The
networks are the chapter's own (trained above or read from the cache), never retrained for the
program.

A program the chapter's machine cannot run (a construct it lacks, a file that is not G-code)
gives a :class:`ProgramResult` with a one-line ``reason`` and nothing else; the rest of the chapter
is unaffected.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path

import numpy as np
import pandas as pd

from ..gcode import read_text
from ..metrics import error_pct
from ..paths import data_dir
from ..report.display import show
from ..toolpath import Toolpath

__all__ = [
    "ProgramResult",
    "block_feeds",
    "block_summary",
    "domain_notes",
    "example_program",
    "program_times",
    "run_program",
    "show_program",
    "show_section",
]


@dataclass(frozen=True)
class ProgramResult:
    """What a chapter's method predicts for one program, beside the chapter's truth.

    Attributes
    ----------
    name : str
        The program's file name.
    times : pandas.DataFrame
        One row per source: ``source``, ``cycle_time_s``, ``err_pct`` (signed, of the truth's
        time; empty for the truth and where there is no truth). Empty when ``reason`` is set.
    feeds : pandas.DataFrame or None
        One row per G-line the method reads: ``line`` (from 1) and one column of average feed
        in mm/s per source (``true_mm_s`` for the truth); None where the method predicts no feed
        per G-line.
    notes : tuple of str
        What the reader needs to read the numbers (which moves the method covers, where the
        program lies outside the training data).
    reason : str or None
        Why the program could not be run (one line), else None.
    """

    name: str
    times: pd.DataFrame = field(default_factory=pd.DataFrame)
    feeds: pd.DataFrame | None = None
    notes: tuple[str, ...] = ()
    reason: str | None = None


def program_times(truth: tuple[str, float] | None, others: dict[str, float]) -> pd.DataFrame:
    """Cycle times with their signed errors against the truth.

    Parameters
    ----------
    truth : (str, float) or None
        The truth's label and cycle time in s; None where the chapter has no truth for a
        program (a real machine that did not run it).
    others : dict
        ``label -> cycle time (s)`` of the method(s) and CAM.

    Returns
    -------
    pandas.DataFrame
        ``source, cycle_time_s, err_pct``; the truth first, with ``err_pct`` NaN.
    """
    rows = [] if truth is None else [{"source": truth[0], "cycle_time_s": truth[1],
                                      "err_pct": np.nan}]  # fmt: skip
    for label, t in others.items():
        err = np.nan if truth is None else error_pct(t, truth[1], signed=True)
        rows.append({"source": label, "cycle_time_s": t, "err_pct": err})
    return pd.DataFrame(rows)


def block_feeds(length_mm: np.ndarray, times_s: dict[str, np.ndarray]) -> pd.DataFrame:
    """Average feed per G-line from each source's time per block: length over time, for the
    blocks that move (dwells and zero-length blocks are left out; a block given no time has
    no average feed, NaN).

    Parameters
    ----------
    length_mm : ndarray, shape (N,)
        Path length of each block.
    times_s : dict
        ``column -> ndarray, shape (N,)``: each source's time per block (``true_mm_s`` for the
        truth's column).

    Returns
    -------
    pandas.DataFrame
        ``line`` (the block's number from 1, among all N) and one column per source, one row
        per moving block.
    """
    moving = length_mm > 0
    out = {"line": np.flatnonzero(moving) + 1}
    for col, t in times_s.items():
        t = np.asarray(t, dtype=float)[moving]
        out[col] = np.divide(length_mm[moving], t, out=np.full(len(t), np.nan), where=t > 0)
    return pd.DataFrame(out)


def block_summary(tp: Toolpath) -> str:
    """``"87 blocks: 8 rapid, 75 linear, 4 arc_ccw"``: a program's blocks by kind (kinds it
    does not have left out)."""
    kinds = ", ".join(f"{n} {kind}" for kind, n in tp.kind_counts().items() if n)
    return f"{len(tp)} blocks: {kinds}"


def run_program(path: str | PathLike, method: Callable[[str, str], ProgramResult]) -> ProgramResult:
    """Read ``path`` and run ``method(text, name)`` on it.

    A file that cannot be read, or a program the method or the chapter's machine refuses (any
    ``ValueError``, :class:`~nctwin.gcode.GCodeError` among them, whose message names the file
    and line), gives a result with that one line as its ``reason``.
    """
    name = Path(path).name
    if Path(path).is_dir():
        return ProgramResult(name, reason=f"{path}: is a directory, not a program")
    if not Path(path).is_file():
        return ProgramResult(name, reason=f"{path}: no such file")
    try:
        text, _ = read_text(path)
        return method(text, str(path))
    except ValueError as exc:
        return ProgramResult(name, reason=str(exc).splitlines()[0])


def show_section(
    heading: str, reason: str | None, table: pd.DataFrame, notes: tuple[str, ...]
) -> bool:
    """The opening every "Your ..." section shares: the heading (Markdown, level 2), then
    ``not run: <reason>``, or the table and the notes. Returns whether the input was run (the
    caller draws its figure then)."""
    from IPython.display import Markdown, display

    display(Markdown(f"## {heading}"))
    if reason is not None:
        print(f"not run: {reason}")
        return False
    show(table)
    for note in notes:
        print(note)
    return True


def example_program() -> Path:
    """The shipped example program, ``data/programs/examples/bracket.ngc``: the "Your program"
    section of each chapter runs it when no program of the reader's is given."""
    return data_dir() / "programs" / "examples" / "bracket.ngc"


def show_program(result: ProgramResult, *, truth_label: str = "truth") -> None:
    """Display the "Your program" section: a heading, then the reason or the table, the notes
    and the average feed per G-line along the program."""
    shown = show_section(f"Your program: `{result.name}`", result.reason, result.times,
                         result.notes)  # fmt: skip
    if shown and result.feeds is not None:
        _plot_feeds(result.feeds, result.name, truth_label)


def _plot_feeds(feeds: pd.DataFrame, name: str, truth_label: str) -> None:
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 3.2), constrained_layout=True)
    cols = [c for c in feeds.columns if c != "line"]
    for i, col in enumerate(cols):
        label = truth_label if col == "true_mm_s" else col.removesuffix("_mm_s")
        style = (
            {"color": "0.3", "lw": 1.0}
            if col == "true_mm_s"
            else {"color": f"C{i}", "lw": 1.0, "ls": "--"}
        )
        ax.plot(feeds["line"], feeds[col], label=label, **style)
    ax.set_xlabel("G-line")
    ax.set_ylabel("average feed (mm/s)")
    ax.set_ylim(bottom=0)
    ax.set_title(f"{name}: average feed per G-line")
    if len(cols) > 3:  # many sources: the legend beside the axes, off the lines
        fig.legend(loc="outside right upper", frameon=False)
    else:
        ax.legend(loc="lower right", frameon=False)
    plt.show()


def domain_notes(
    x: np.ndarray, x_train: np.ndarray, names: tuple[str, ...], *, rows: str = "G-lines"
) -> tuple[str, ...]:
    """Where a program's inputs leave the training data: one line naming each input with values
    outside the range the networks were trained on, and the share of rows that have them.

    Parameters
    ----------
    x : ndarray, shape (N, D)
        The program's inputs, one row per G-line (or cutter location).
    x_train : ndarray, shape (M, D)
        The training inputs.
    names : tuple of str, length D
        The inputs' names.
    rows : str
        What a row is, for the text.

    Returns
    -------
    tuple of str
        Empty when every input lies inside its training range, else one line, ``"outside the
        training range (share of the <rows>): <name> <share> % (<lo> to <hi>), ..."``.
    """
    lo, hi = np.nanmin(x_train, axis=0), np.nanmax(x_train, axis=0)
    share = 100 * ((x < lo) | (x > hi)).mean(axis=0)
    parts = [f"{name} {share[j]:.3g} % ({lo[j]:.4g} to {hi[j]:.4g})"
             for j, name in enumerate(names) if share[j] > 0]  # fmt: skip
    if not parts:
        return ()
    return (f"outside the training range (share of the {rows}): " + ", ".join(parts),)
