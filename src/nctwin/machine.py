"""Machine profiles: what a machine tool and its control are, loaded from ``data/machines/*.toml``.

A :class:`MachineProfile` holds what a control's machine data hold: axis limits, rapid and maximum
feed, interpolation period, default blending tolerance, the time constants of its acc/dec filters
and its servo loops. Every value is checked on construction; a bad one raises :class:`ValueError`
naming the field, the value and the allowed range.

How a virtual kernel interpolates the machine is not part of it: a profile's file may hold a
kernel's settings in a table of their own (``[fir]`` for :class:`nctwin.kernel.fir.FirSettings`),
read by :func:`load_table`.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import MISSING, dataclass, fields
from pathlib import Path

from .paths import data_dir

__all__ = [
    "DEFAULT_MACHINE",
    "MachineProfile",
    "available_machines",
    "load_machine",
    "load_table",
    "profile_path",
    "whole_periods",
]

#: Profile used when none is named.
DEFAULT_MACHINE = "generic_mill"
#: Tables of a profile's file that hold a kernel's settings (see :func:`load_table`).
KERNEL_TABLES = ("fir", "fanuc")

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
    cut_time_constant_s: float = 0.05
    rapid_time_constant_s: float = 0.1
    rapid_bell_s: float = 0.0
    rapid_type: str = "linear"
    position_gain_per_s: _XYZ = (30.0, 30.0, 30.0)
    inposition_width_mm: _XYZ = (0.02, 0.02, 0.02)
    inposition_time_s: _XYZ = (0.0, 0.0, 0.0)

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
        for f in ("cut_time_constant_s", "rapid_time_constant_s"):
            _check(f, getattr(self, f), 0.0, 10.0, lo_closed=True, hi_closed=True)
        _check("rapid_bell_s", self.rapid_bell_s, 0.0, 10.0, lo_closed=True, hi_closed=True)
        if self.rapid_type not in ("linear", "nonlinear"):
            raise ValueError(
                f"rapid_type = {self.rapid_type!r} is not allowed: allowed 'linear', 'nonlinear'"
            )

    @classmethod
    def from_toml(cls, path: str | Path) -> MachineProfile:
        """Read a profile from a TOML file (keys as the dataclass fields; ``name`` defaults to
        the file's stem; the tables of :data:`KERNEL_TABLES` are a kernel's, not the
        profile's)."""
        p = Path(path)
        data = {k: v for k, v in _read_toml(p).items() if k not in KERNEL_TABLES}
        allowed = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - allowed)
        if unknown:
            raise ValueError(
                f"{p}: unknown field(s) {', '.join(unknown)}; allowed: {', '.join(sorted(allowed))}"
            )
        data.setdefault("name", p.stem)
        missing = [f.name for f in fields(cls) if f.default is MISSING and f.name not in data]
        if missing:
            raise ValueError(f"{p}: missing field(s) {', '.join(missing)}")
        try:
            return cls(**data)
        except ValueError as exc:
            raise ValueError(f"{p}: {exc}") from None


def _read_toml(p: Path) -> dict:
    try:
        with p.open("rb") as fh:
            return tomllib.load(fh)
    except OSError as exc:
        raise ValueError(f"cannot read machine profile {p}: {exc.strerror or exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"machine profile {p} is not valid TOML: {exc}") from None


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


def profile_path(name: str | Path | None = None) -> Path:
    """The file of a shipped profile by name, or a profile file by path (``.toml``).

    Parameters
    ----------
    name : str or Path, optional
        A name from :func:`available_machines`, or a path to a ``.toml`` file. Default:
        :data:`DEFAULT_MACHINE`.

    Raises
    ------
    ValueError
        If ``name`` is neither.
    """
    name = DEFAULT_MACHINE if name is None else name
    p = Path(name)
    if p.suffix == ".toml" or p.exists():
        return p
    shipped = machines_dir() / f"{name}.toml"
    if not shipped.exists():
        raise ValueError(
            f"machine = {str(name)!r} is unknown: allowed "
            f"{', '.join(available_machines())} or a path to a .toml file"
        )
    return shipped


def load_machine(name: str | Path | None = None) -> MachineProfile:
    """Load a shipped profile by name, or a profile file by path (see :func:`profile_path`)."""
    return MachineProfile.from_toml(profile_path(name))


def load_table(name: str | Path | None, table: str) -> dict:
    """A kernel's table of a profile's file (one of :data:`KERNEL_TABLES`); empty if the file
    has none."""
    if table not in KERNEL_TABLES:
        raise ValueError(f"table = {table!r} is unknown: allowed {', '.join(KERNEL_TABLES)}")
    p = profile_path(name)
    data = _read_toml(p).get(table, {})
    if not isinstance(data, dict):
        raise ValueError(f"{p}: {table} must be a table ([{table}])")
    return data
