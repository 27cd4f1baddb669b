"""Writing a tool path back as a program: :func:`dump`."""

from __future__ import annotations

import numpy as np

from ..toolpath import PLANE_AXES, MotionKind, PathMode, Plane, Toolpath


def _num(x: float) -> str:
    """Shortest decimal that reads back to the same float, never in exponent form."""
    return np.format_float_positional(x, unique=True, trim="-")


def dump(tp: Toolpath, *, title: str | None = None) -> str:
    """Write a tool path as a program: mm, absolute coordinates, absolute arc centres.

    ``parse(dump(tp))`` gives a tool path that :meth:`Toolpath.allclose` calls equal to ``tp``.

    Parameters
    ----------
    tp : Toolpath
    title : str, optional
        A comment for the first line.

    Returns
    -------
    str
    """
    out = [f"({title})" if title else "(written by nctwin)", "G21 G90 G90.1 G94 G17"]
    plane, feed, path = int(Plane.XY), np.nan, (int(PathMode.DEFAULT), np.nan, np.nan)
    events = tp.events[tp.events["word"] != "G"]  # the offsets are in the positions already
    ei = 0
    for k in range(len(tp)):
        while ei < len(events) and events["block"][ei] <= k:
            out.append(f"{events['word'][ei]}{_num(events['value'][ei])}")
            ei += 1
        mode = (int(tp.path_mode[k]), tp.blend_tol_mm[k], tp.naive_tol_mm[k])
        if not (mode[0] == path[0] and np.array_equal(mode[1:], path[1:], equal_nan=True)):
            if mode[0] == PathMode.BLEND:
                out.append(
                    "G64"
                    + "".join(
                        f" {w}{_num(v)}"
                        for w, v in zip("PQ", mode[1:], strict=True)
                        if not np.isnan(v)
                    )
                )
            elif mode[0] != PathMode.DEFAULT:
                out.append("G61" if mode[0] == PathMode.EXACT_PATH else "G61.1")
            else:
                raise ValueError("a tool path cannot return to the machine's default path mode")
            path = mode
        kind = tp.kind[k]
        words = []
        f = tp.feed_mm_s[k]
        if not np.isnan(f) and f != feed:
            words.append(f"F{_num(f * 60.0)}")
            feed = f
        if kind == MotionKind.DWELL:
            out += [*words, f"G4 P{_num(tp.dwell_s[k])}"]
            continue
        if tp.is_arc[k] and tp.plane[k] != plane:
            plane = int(tp.plane[k])
            words.append(f"G{17 + plane}")
        words.append(("G0", "G1", "G2", "G3")[kind])
        words += [f"{a}{_num(v)}" for a, v in zip("XYZ", tp.end_mm[k], strict=True)]
        if tp.is_arc[k]:
            ax = PLANE_AXES[plane]
            words += [f"{'IJK'[a]}{_num(tp.center_mm[k, a])}" for a in ax[:2]]
        out.append(" ".join(words))
    out += [f"{w}{_num(v)}" for w, v in zip(events["word"][ei:], events["value"][ei:], strict=True)]
    return "\n".join(out) + "\n"
