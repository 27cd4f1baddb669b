"""Figures. Computing happens elsewhere; these functions only draw what they are given."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FeedPlot", "feed_figure"]


@dataclass(frozen=True, eq=False)
class FeedPlot:
    """What :func:`feed_figure` draws, in the units it labels (computed by the caller, e.g.
    ``nctwin simulate --plot``).

    Parameters
    ----------
    t_s : ndarray, shape (n,)
        Sample times.
    commanded : ndarray, shape (n,)
        Programmed feed of the block each sample executes, in ``feed_unit`` (NaN in dwells).
    actual : ndarray, shape (n,)
        Simulated feed (path speed) of each sample, in ``feed_unit``.
    rapid : ndarray of bool, shape (n,)
        Whether each sample executes a rapid.
    xy : ndarray, shape (n, 2)
        Sampled X and Y, in ``length_unit``.
    rapid_xy : ndarray, shape (R, 2, 2)
        Start and end (X, Y) of each commanded rapid move, in ``length_unit``.
    feed_top : float
        Upper end of the feed axis and of the colour scale, in ``feed_unit``: a little above
        the highest cutting feed, so that rapids are clipped.
    rapid_feed : float
        The machine's rapid feed, in ``feed_unit`` (written on the figure).
    feed_unit, length_unit : str
        Labels, e.g. ``"mm/min"`` and ``"mm"``.
    title : str, optional
    """

    t_s: np.ndarray
    commanded: np.ndarray
    actual: np.ndarray
    rapid: np.ndarray
    xy: np.ndarray
    rapid_xy: np.ndarray
    feed_top: float
    rapid_feed: float
    feed_unit: str
    length_unit: str
    title: str | None = None


def _around(mask: np.ndarray) -> np.ndarray:
    """``mask`` widened by one sample on each side (so that pieces of a line join)."""
    out = mask.copy()
    out[1:] |= mask[:-1]
    out[:-1] |= mask[1:]
    return out


def _number(value: float) -> str:
    """A feed for a label: whole units from 100 up, three digits below."""
    return f"{value:.0f}" if abs(value) >= 100 else f"{value:.3g}"


def feed_figure(plot: FeedPlot):
    """Two panels: (a) the feed over time, scaled to the cutting moves (rapids dashed, faint
    and clipped, with a note of the rapid feed); (b) the tool path in XY coloured by the
    simulated feed, rapids dashed grey: where the time goes.

    Returns
    -------
    matplotlib.figure.Figure
        Its axes are the time panel, the XY panel and the colour bar, in that order.
    """
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    fig, (ax_t, ax_xy) = plt.subplots(
        1, 2, figsize=(13, 5), width_ratios=(1.6, 1.0), constrained_layout=True
    )
    unit, top = plot.feed_unit, plot.feed_top
    cut = ~plot.rapid
    rapid_near = _around(plot.rapid)

    # (a) feed over time
    ax_t.plot(
        plot.t_s, np.where(cut, plot.commanded, np.nan), lw=1.0, color="0.55", label="programmed"
    )
    ax_t.plot(
        plot.t_s, np.where(_around(cut), plot.actual, np.nan), lw=1.0, color="C0", label="simulated"
    )
    if plot.rapid.any():
        clipped = ", clipped" if float(plot.actual[plot.rapid].max()) > top else ""
        ax_t.plot(
            plot.t_s,
            np.where(rapid_near, plot.actual, np.nan),
            lw=0.8,
            ls="--",
            color="C0",
            alpha=0.4,
            label=f"rapid{clipped} (rapid feed {_number(plot.rapid_feed)} {unit})",
        )
    ax_t.set_xlabel("time (s)")
    ax_t.set_ylabel(f"feed ({unit})")
    ax_t.set_xlim(0, max(float(plot.t_s[-1]) if len(plot.t_s) else 0.0, 1e-3))
    ax_t.set_ylim(0, top)
    ax_t.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), ncols=3, frameon=False, fontsize=8)
    ax_t.set_title("(a) feed over time", loc="left", fontsize=10, pad=18)

    # (b) the path in XY, coloured by the simulated feed
    both = cut[:-1] & cut[1:]
    segments = np.stack([plot.xy[:-1][both], plot.xy[1:][both]], axis=1)
    speed = 0.5 * (plot.actual[:-1] + plot.actual[1:])[both]
    lines = LineCollection(segments, cmap="viridis", linewidths=1.2)
    lines.set_array(speed)
    lines.set_clim(0, top)
    ax_xy.add_collection(lines)
    if len(plot.rapid_xy):
        r = plot.rapid_xy
        gaps = np.full((len(r), 1), np.nan)
        x = np.hstack([r[:, :, 0], gaps]).ravel()
        y = np.hstack([r[:, :, 1], gaps]).ravel()
        ax_xy.plot(x, y, ls="--", lw=0.8, color="0.6", label="rapid")
        ax_xy.legend(loc="upper right", frameon=False, fontsize=8)
    ax_xy.autoscale_view()
    ax_xy.set_aspect("equal", adjustable="datalim")
    ax_xy.set_xlabel(f"X ({plot.length_unit})")
    ax_xy.set_ylabel(f"Y ({plot.length_unit})")
    ax_xy.set_title("(b) tool path, coloured by the simulated feed", loc="left", fontsize=10)
    extend = "max" if len(speed) and float(speed.max()) > top else "neither"
    fig.colorbar(lines, ax=ax_xy, label=f"feed ({unit})", extend=extend, shrink=0.9)
    if plot.title:
        fig.suptitle(plot.title, fontsize=11)
    return fig
