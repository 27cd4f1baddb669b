"""The reader's errors: :class:`GCodeError`, and :class:`_Errors`, which collects every error
of a program and raises them at once, in line order, up to :data:`MAX_ERRORS`; and the check of
the readers' point arguments."""

from __future__ import annotations

import numpy as np

#: Errors listed in a :class:`GCodeError`'s message; the rest are counted.
MAX_ERRORS = 20
_NEEDS_LINUXCNC = "needs LinuxCNC's interpreter: run make linuxcnc"
#: What replaces :data:`_NEEDS_LINUXCNC` in the fanuc dialect, where LinuxCNC's interpreter,
#: which reads RS274/NGC only, cannot help.
_NOT_FANUC = "is not supported in the fanuc dialect"


class GCodeError(ValueError):
    """A program that cannot be read: where, what and why, for each error found.

    Parameters
    ----------
    line : int
        1-based line number of the first error (0 when the error is not tied to a line).
    text : str
        The offending line as written.
    reason : str
        What is wrong, naming the construct.
    source : str, optional
        File name, for messages.
    errors : sequence of GCodeError, optional
        Every error listed, first one first (default: this one alone).
    n_more : int
        Errors found beyond those listed.

    Attributes
    ----------
    errors : tuple of GCodeError
        The errors listed, one per line, in line order.

    Notes
    -----
    The message has one ``file:line: reason`` line per listed error, then ``... and N more``.
    """

    def __init__(
        self,
        line: int,
        text: str,
        reason: str,
        source: str | None = None,
        errors: tuple[GCodeError, ...] | list[GCodeError] = (),
        n_more: int = 0,
    ) -> None:
        self.line, self.text, self.reason, self.source = line, text, reason, source
        self.errors = tuple(errors) or (self,)
        self.n_more = n_more
        super().__init__(str(self))

    def __str__(self) -> str:
        out = [f"{e.source or '<string>'}:{e.line}: {e.reason}" for e in self.errors]
        if self.n_more:
            out.append(f"... and {self.n_more} more")
        return "\n".join(out)


class _Errors:
    """The errors found: per check, the lines (and text positions) it hit and its reason.

    Lexical errors (keyed by their position in the text) come before the other errors of their
    line; one error is kept per line, the earliest; :meth:`raise_all` raises them in line order.
    """

    def __init__(self, raw_lines: list[str], line_starts: np.ndarray, source: str | None):
        self.raw_lines, self.line_starts, self.source = raw_lines, line_starts, source
        self.found: list[tuple[np.ndarray, np.ndarray, np.ndarray, object]] = []
        self.fanuc = False  # the fanuc dialect: no reason sends the reader to LinuxCNC's

    def at_pos(self, pos: np.ndarray, reason) -> None:
        """Record ``reason`` (a string, or a function of the position) at text positions."""
        pos = np.asarray(pos, dtype=np.int64)
        if len(pos):
            lines = np.searchsorted(self.line_starts, pos, side="right") - 1
            self.found.append((lines, np.zeros(len(pos), np.int64), pos, reason))

    def at_lines(self, mask: np.ndarray, reason) -> None:
        """Record ``reason`` (a string, or a function of the line index) at the lines of
        ``mask`` (a boolean mask, or line indices)."""
        lines = np.flatnonzero(mask) if mask.dtype == bool else np.asarray(mask, np.int64)
        if len(lines):
            order = np.full(len(lines), len(self.found), np.int64)
            self.found.append((lines, np.ones(len(lines), np.int64), order, reason))

    def raise_all(self, n_lines: int) -> None:
        """Raise the errors of lines ``0..n_lines-1``, if any, as one :class:`GCodeError`."""
        if not self.found:
            return
        item = np.concatenate([np.full(len(f[0]), i) for i, f in enumerate(self.found)])
        hit = np.concatenate([np.arange(len(f[0])) for f in self.found])
        line, stage, key = (np.concatenate([f[k] for f in self.found]) for k in range(3))
        order = np.lexsort((key, stage, line))
        line, item, hit, stage = line[order], item[order], hit[order], stage[order]
        first = np.flatnonzero(np.concatenate([[True], line[1:] != line[:-1]]) & (line < n_lines))
        if not len(first):
            return
        errors = []
        for k in first[:MAX_ERRORS]:
            _, _, keys, reason = self.found[item[k]]
            i = int(line[k])
            if callable(reason):
                reason = reason(int(keys[hit[k]]) if stage[k] == 0 else i)
            if self.fanuc:
                reason = reason.replace(_NEEDS_LINUXCNC, _NOT_FANUC)
            text = self.raw_lines[i] if i < len(self.raw_lines) else ""
            errors.append(GCodeError(i + 1, text, reason, self.source))
        e = errors[0]
        raise GCodeError(e.line, e.text, e.reason, self.source, errors, len(first) - len(errors))


def _point_mm(name: str, value) -> np.ndarray:
    """A keyword argument that is a point (3 finite numbers, mm) as an array.

    Raises
    ------
    ValueError
        Naming the argument and its value, if it is not 3 finite numbers.
    """
    try:
        point = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        point = np.zeros(0)
    if point.shape != (3,) or not np.isfinite(point).all():
        raise ValueError(f"{name} must be 3 finite numbers, got {value!r}")
    return point
