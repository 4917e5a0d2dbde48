"""How numbers are written into generated model files (MJCF, URDF): one formatter for every model's generator."""

from __future__ import annotations


def number(x: float, digits: int | None = None) -> str:
    """`x` as model-file text. `digits=None`: the shortest text that reads back as the same double (Python's `repr`,
    e.g. '0.944', '1.0', '-0.0'); an int: rounded to that many significant digits, a zero of either sign written '0'
    (e.g. digits=15: '0.944', '1', '0')."""
    if digits is None:
        return repr(float(x))
    s = f"{float(x):.{digits}g}"
    return "0" if s in ("-0", "0") else s
