"""Machine profiles: the settings of a virtual machine tool, loaded from ``data/machines/*.toml``.

A :class:`MachineProfile` holds what a control's machine data hold: axis limits, rapid and maximum
feed, interpolation period, default blending tolerance and the time constants of its acc/dec
filters. Every value is checked on construction; a bad one raises :class:`ValueError` naming the
field, the value and the allowed range.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path

from .paths import data_dir

__all__ = [
    "DEFAULT_MACHINE",
    "MachineProfile",
    "available_machines",
    "load_machine",
    "whole_periods",
]

#: Profile used when none is named.
DEFAULT_MACHINE = "generic_mill"

_XYZ = tuple[float, float, float]


@dataclass(frozen=True)
class MachineProfile:
    """Settings of a 3-axis machine tool and its control.

    Parameters
    ----------
    name : str
        Short name (the TOML file's stem).
    description : str
        What the profile stands for.
    axis_max_velocity_mm_s : tuple of 3 floats
        Velocity limit of X, Y, Z.
    axis_max_acceleration_mm_s2 : tuple of 3 floats
        Acceleration limit of X, Y, Z.
    axis_max_jerk_mm_s3 : tuple of 3 floats
        Jerk limit of X, Y, Z; ``inf`` for a control without jerk limitation.
    rapid_feed_mm_s : float
        Path feed of rapid (G0) moves.
    max_feed_mm_s : float
        Highest programmable feed; a larger F is clamped to it.
    period_s : float
        Interpolation period.
    blend_tol_mm : float
        Corner-blending tolerance used where the program sets none (G64 P overrides it).
    fir_t1_s, fir_t2_s : float
        Time constants of the FIR interpolator: acceleration ``F / T1``, jerk ``F / (T1 T2)``.
    fir_acc_scale : float
        The FIR kernel enforces the axis accelerations times this (1 for the kernel's own
        machines; fitted where the kernel stands in for another control).
    fir_blend_ratio : float
        The FIR kernel blends a junction within at most this share of the shorter of its two
        moves (a plain ``G64`` within this alone); ``inf``: the program's tolerance only.
    fir_block_periods : int
        Shortest time of a move on the FIR kernel, in periods (a control's block-processing
        rate): a move of length ``l`` runs at most at ``l / (n period_s)``; 0: no limit.
    cut_time_constant_s : float
        Acc/dec time constant of cutting feed (linear type, after interpolation).
    rapid_time_constant_s : float
        Acc/dec time constant of rapids.
    rapid_bell_s : float
        Bell-shaped (S-curve) stage added to rapids; 0 for none.
    rapid_type : {"linear", "nonlinear"}
        Path of rapids: a straight line at the rapid feed (linear interpolation type), or each
        axis on its own at the rapid feed (non-linear type, Lee et al. 2022, Fig. 3).
    position_gain_per_s : tuple of 3 floats
        Position-loop gain Kp of X, Y, Z (first-order loop: following error decays as
        ``exp(-Kp t)``).
    inposition_width_mm : tuple of 3 floats
        In-position width of X, Y, Z: after a rapid, the next block waits until every axis's
        following error is within it.
    inposition_time_s : tuple of 3 floats
        Measured in-position time of X, Y, Z after a rapid, used by analytic estimators
        (Lee et al. 2022, Sec. 2.3); 0 where not measured.
    default_method : str
        Estimator ``nctwin estimate`` uses when none is named: the best one the chapter that
        measured this machine found (``cam`` where none did).
    """

    name: str
    description: str
    axis_max_velocity_mm_s: _XYZ
    axis_max_acceleration_mm_s2: _XYZ
    axis_max_jerk_mm_s3: _XYZ
    rapid_feed_mm_s: float
    max_feed_mm_s: float
    period_s: float = 0.001
    blend_tol_mm: float = 0.05
    fir_t1_s: float = 0.05
    fir_t2_s: float = 0.01
    fir_acc_scale: float = 1.0
    fir_blend_ratio: float = math.inf
    fir_block_periods: int = 0
    cut_time_constant_s: float = 0.05
    rapid_time_constant_s: float = 0.1
    rapid_bell_s: float = 0.0
    rapid_type: str = "linear"
    position_gain_per_s: _XYZ = (30.0, 30.0, 30.0)
    inposition_width_mm: _XYZ = (0.02, 0.02, 0.02)
    inposition_time_s: _XYZ = (0.0, 0.0, 0.0)
    default_method: str = "cam"

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"name = {self.name!r} must be a non-empty string")
        for f in (
            "axis_max_velocity_mm_s",
            "axis_max_acceleration_mm_s2",
            "axis_max_jerk_mm_s3",
            "position_gain_per_s",
            "inposition_width_mm",
            "inposition_time_s",
        ):
            v = getattr(self, f)
            try:
                v = tuple(float(x) for x in v)
            except (TypeError, ValueError):
                raise ValueError(f"{f} = {v!r} must be three numbers (X, Y, Z)") from None
            if len(v) != 3:
                raise ValueError(f"{f} = {v!r} must be three numbers (X, Y, Z)")
            allow_inf = f == "axis_max_jerk_mm_s3"
            lo_closed = f == "inposition_time_s"
            hi = 10.0 if lo_closed else math.inf
            for axis, x in zip("XYZ", v, strict=True):
                _check(f"{f}[{axis}]", x, 0.0, hi, lo_closed=lo_closed, allow_inf=allow_inf)
            object.__setattr__(self, f, v)
        _check("rapid_feed_mm_s", self.rapid_feed_mm_s, 0.0, math.inf)
        _check("max_feed_mm_s", self.max_feed_mm_s, 0.0, math.inf)
        _check("period_s", self.period_s, 0.0, 0.1, hi_closed=True)
        _check("blend_tol_mm", self.blend_tol_mm, 0.0, 10.0, lo_closed=True, hi_closed=True)
        for f in ("fir_t1_s", "fir_t2_s", "cut_time_constant_s", "rapid_time_constant_s"):
            _check(f, getattr(self, f), 0.0, 10.0, lo_closed=True, hi_closed=True)
        _check("rapid_bell_s", self.rapid_bell_s, 0.0, 10.0, lo_closed=True, hi_closed=True)
        _check("fir_acc_scale", self.fir_acc_scale, 0.0, 100.0)
        _check("fir_blend_ratio", self.fir_blend_ratio, 0.0, 1.0, hi_closed=True, allow_inf=True)
        if not isinstance(self.fir_block_periods, int) or not 0 <= self.fir_block_periods <= 100:
            raise ValueError(
                f"fir_block_periods = {self.fir_block_periods!r} is out of range: "
                "allowed integers in [0, 100]"
            )
        if self.rapid_type not in ("linear", "nonlinear"):
            raise ValueError(
                f"rapid_type = {self.rapid_type!r} is not allowed: allowed 'linear', 'nonlinear'"
            )

    @classmethod
    def from_toml(cls, path: str | Path) -> MachineProfile:
        """Read a profile from a TOML file (keys as the dataclass fields; ``name`` defaults to
        the file's stem)."""
        p = Path(path)
        try:
            with p.open("rb") as fh:
                data = tomllib.load(fh)
        except OSError as exc:
            raise ValueError(f"cannot read machine profile {p}: {exc.strerror or exc}") from None
        except tomllib.TOMLDecodeError as exc:
            raise ValueError(f"machine profile {p} is not valid TOML: {exc}") from None
        allowed = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - allowed)
        if unknown:
            raise ValueError(
                f"{p}: unknown field(s) {', '.join(unknown)}; allowed: {', '.join(sorted(allowed))}"
            )
        data.setdefault("name", p.stem)
        try:
            return cls(**data)
        except TypeError as exc:  # a required field is missing
            raise ValueError(f"{p}: {exc}") from None
        except ValueError as exc:
            raise ValueError(f"{p}: {exc}") from None


def _check(
    name: str,
    value,
    lo: float,
    hi: float,
    *,
    lo_closed: bool = False,
    hi_closed: bool = False,
    allow_inf: bool = False,
) -> None:
    """Raise ValueError unless ``value`` is a number in the given interval."""
    ok = isinstance(value, int | float) and not isinstance(value, bool) and not math.isnan(value)
    if ok and not (allow_inf and value == math.inf):
        ok = (lo <= value if lo_closed else lo < value) and (
            value <= hi if hi_closed else value < hi
        )
    if not ok:
        interval = f"{'[' if lo_closed else '('}{lo:g}, {hi:g}{']' if hi_closed else ')'}"
        extra = " or inf" if allow_inf else ""
        raise ValueError(f"{name} = {value!r} is out of range: allowed {interval}{extra}")


def whole_periods(name: str, value_s: float, period_s: float) -> int:
    """A time setting as a whole number of interpolation periods.

    Raises
    ------
    ValueError
        Naming the setting, its value and the allowed values, if it is not a whole multiple.
    """
    k = round(value_s / period_s)
    if not math.isclose(k * period_s, value_s, rel_tol=1e-9, abs_tol=1e-12):
        raise ValueError(
            f"{name} = {value_s!r} is out of range: allowed whole multiples of "
            f"period_s = {period_s!r}"
        )
    return k


def machines_dir() -> Path:
    """Folder of the shipped profiles."""
    return data_dir() / "machines"


def available_machines() -> list[str]:
    """Names of the shipped profiles."""
    return sorted(p.stem for p in machines_dir().glob("*.toml"))


def load_machine(name: str | Path | None = None) -> MachineProfile:
    """Load a shipped profile by name, or a profile file by path.

    Parameters
    ----------
    name : str or Path, optional
        A name from :func:`available_machines`, or a path to a ``.toml`` file. Default:
        :data:`DEFAULT_MACHINE`.
    """
    name = DEFAULT_MACHINE if name is None else name
    p = Path(name)
    if p.suffix == ".toml" or p.exists():
        return MachineProfile.from_toml(p)
    shipped = machines_dir() / f"{name}.toml"
    if not shipped.exists():
        raise ValueError(
            f"machine = {str(name)!r} is unknown: allowed "
            f"{', '.join(available_machines())} or a path to a .toml file"
        )
    return MachineProfile.from_toml(shipped)
