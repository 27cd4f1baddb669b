"""nctwin: reproducing machine-learning and analytic prediction in NC machining."""

from .gcode import GCodeError, dump, parse, parse_file
from .toolpath import MotionKind, PathMode, Plane, Toolpath

__all__ = [
    "GCodeError",
    "MotionKind",
    "PathMode",
    "Plane",
    "Toolpath",
    "dump",
    "parse",
    "parse_file",
]
__version__ = "0.1.0"
