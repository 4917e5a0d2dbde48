"""Valid ranges declared beside each value: one `Limit` per parameter field, scene input key and CLI number.

A parameter dataclass declares its fields with `param(default, lo=..., hi=..., unit=..., doc=...)`; its
`__post_init__` calls `check_fields(self, "pantograph parameter")`. Scene input keys are declared the same way
(`Limit(...)` in `ModelSpec.inputs`). The scene validator, the error messages and the docs (`limits_table`) all read the
same declaration, so a range is written once.

Numbers must be finite real numbers; a range end may be open or closed. What counts as a number is `real`: every
real number type a Python or numpy user passes (int, float, `fractions.Fraction`, `decimal.Decimal`, numpy integers
and floats of every width, 0-d arrays of them), taken as the Python int or float it holds. Bools (Python's and
numpy's) are not numbers here, so true/false is never taken for 1/0; complex numbers are refused even with a zero
imaginary part.

numpy is not imported here: a value can only be a numpy one once numpy is loaded (`_numpy`), so that a declaration
(a command's options, for its --help) loads no numpy.
"""

from __future__ import annotations

import dataclasses
import decimal
import math
import numbers
import sys
from collections.abc import Iterable
from dataclasses import dataclass
from types import ModuleType
from typing import Any

from .errors import ParameterError

_NO_DEFAULT = object()


def _numpy() -> ModuleType | None:
    """numpy if it is loaded, else None (then no value is a numpy one)."""
    return sys.modules.get("numpy")


def real(value: Any) -> int | float | None:
    """`value` as the Python int or float it holds if it is a real number of any type (see the module docstring),
    else None (bools, complex numbers, strings, containers). Integral types give an int, the others a float; numpy's
    float16/float32 give the shortest decimal that reads back as the same narrow float (`np.float32(0.001)` is
    0.001, the number the user wrote, not its binary neighbour 0.0010000000474974513). A Fraction or Decimal too
    large for a float gives inf (then refused as not finite)."""
    np = _numpy()
    if np is not None and isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    if isinstance(value, bool) or np is not None and isinstance(value, np.bool_):
        return None
    if isinstance(value, numbers.Integral):
        return int(value)
    if np is not None and isinstance(value, np.floating) and value.dtype.itemsize < 8:
        return float(str(value))
    if isinstance(value, numbers.Real | decimal.Decimal):
        try:
            return float(value)
        except OverflowError:
            return math.inf if value > 0 else -math.inf
        except ValueError:  # a signalling Decimal NaN
            return math.nan
    return None


@dataclass(frozen=True)
class Limit:
    """The valid values of one number or word.

    - `kind`: `float` (any finite real), `int` (an integral number), `str` (one of `choices`, or any text without
      them) or `bool` (true or false only);
    - `lo`, `hi`: range ends (None: unbounded), open when `lo_open` / `hi_open`;
    - `choices`: allowed values for `str` (or a fixed set of numbers);
    - `unit`: SI unit, `doc`: one line; `default`: the value used when a scene omits the key (shown in outputs).
    """

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    unit: str = ""
    doc: str = ""
    kind: type = float
    choices: tuple[Any, ...] | None = None
    default: Any = _NO_DEFAULT

    def optional(self) -> Limit:
        """This limit without its default (a key that may be absent, its absence meaning something else)."""
        return dataclasses.replace(self, default=_NO_DEFAULT)

    @property
    def has_default(self) -> bool:
        """True when a default is declared (the scene loader then fills it in)."""
        return self.default is not _NO_DEFAULT

    def describe(self) -> str:
        """The valid range in words, e.g. `(0, inf) m` or `one of ['equilibrium', 'fortran']`."""
        if self.kind is bool:
            return "true or false"
        if self.kind is str and self.choices is None:
            return "text"
        if self.choices is not None:
            return f"one of {list(self.choices)}"
        lo = "-inf" if self.lo is None else f"{self.lo:g}"
        hi = "inf" if self.hi is None else f"{self.hi:g}"
        left = "(" if (self.lo is None or self.lo_open) else "["
        right = ")" if (self.hi is None or self.hi_open) else "]"
        kind = "integer in " if self.kind is int else ""
        return f"{kind}{left}{lo}, {hi}{right}" + (f" {self.unit}" if self.unit else "")

    def check(self, name: str, value: Any, error: type[Exception] = ParameterError, where: str = "") -> Any:
        """Return `value` (as float/int/str) if valid, else raise `error` naming `name`, the value, where it came from
        (`where`, a phrase with a leading space) and the range."""
        bad = f"{name} = {value!r}{where} is invalid; valid: {self.describe()}"
        if self.kind is bool:
            np = _numpy()
            if not (isinstance(value, bool) or np is not None and isinstance(value, np.bool_)):
                raise error(bad)
            return bool(value)
        if self.kind is str or (self.choices is not None and all(isinstance(c, str) for c in self.choices)):
            if not isinstance(value, str) or (self.choices is not None and value not in self.choices):
                raise error(bad)
            return value
        number = real(value)
        if number is None:
            raise error(f"{name} = {value!r}{where} is not a number; valid: {self.describe()}")
        value = number
        if not math.isfinite(value):
            raise error(bad)
        if self.kind is int:
            if float(value) != int(value):
                raise error(bad)
            value = int(value)
        else:
            value = float(value)
        if self.choices is not None and value not in self.choices:
            raise error(bad)
        if self.lo is not None and (value < self.lo or (self.lo_open and value == self.lo)):
            raise error(bad)
        if self.hi is not None and (value > self.hi or (self.hi_open and value == self.hi)):
            raise error(bad)
        return value


def positive(unit: str = "", doc: str = "", hi: float | None = None, **kw: Any) -> Limit:
    """A number > 0 (optionally <= hi)."""
    return Limit(lo=0.0, lo_open=True, hi=hi, unit=unit, doc=doc, **kw)


def param(default: Any = _NO_DEFAULT, *, lo: float | None = None, hi: float | None = None, lo_open: bool = False,
          hi_open: bool = False, unit: str = "", doc: str = "", kind: type = float,
          choices: tuple[Any, ...] | None = None, draw: str | None = None) -> Any:
    """A dataclass field with its valid range: `l1: float = param(1.95, lo=0, lo_open=True, unit="m", doc=...)`.
    `draw`: the key of its perturbation draw when it is shared (`perturbation.POSITION`: coordinates that coincide
    across objects). Without `default` the field is required (a quantity of the user's own design: no default)."""
    lim = Limit(lo=lo, hi=hi, lo_open=lo_open, hi_open=hi_open, unit=unit, doc=doc, kind=kind, choices=choices,
                default=default)
    if isinstance(default, list | dict | set):
        raise TypeError("param() defaults must be immutable")
    metadata = {"limit": lim, **({"draw": draw} if draw else {})}
    if default is _NO_DEFAULT:
        return dataclasses.field(metadata=metadata)
    return dataclasses.field(default=default, metadata=metadata)


def limit_of(cls_or_obj: Any, name: str) -> Limit | None:
    """The declared `Limit` of dataclass field `name` (None if the field declares none)."""
    for f in dataclasses.fields(cls_or_obj):
        if f.name == name:
            return f.metadata.get("limit")
    raise KeyError(name)


def check_fields(obj: Any, owner: str, error: type[Exception] = ParameterError) -> None:
    """Check every field of dataclass instance `obj` that declares a `Limit`; coerce ints to floats where the field
    is a float (frozen dataclasses are updated with `object.__setattr__`). Errors read `<owner> <field> = ...`. A field
    whose default is None may be left None (unset: its owner derives the value)."""
    for f in dataclasses.fields(obj):
        lim = f.metadata.get("limit")
        if lim is None or (f.default is None and getattr(obj, f.name) is None):
            continue
        v = lim.check(f"{owner} {f.name}", getattr(obj, f.name), error)
        if v is not getattr(obj, f.name):
            object.__setattr__(obj, f.name, v)
    perturbation = sys.modules.get(f"{__package__}.trust.perturbation")  # not loaded: not inside `perturbed`
    if perturbation is not None:
        perturbation.fields(obj)  # inside `perturbation.perturbed` (the stability check) every float is perturbed


def limits_table(cls: Any) -> list[tuple[str, str, str, str, str]]:
    """Rows (name, default, valid range, unit, doc) of every declared field: for docs and `mbsuite list --params`."""
    rows = []
    for f in dataclasses.fields(cls):
        lim = f.metadata.get("limit")
        if lim is None:
            continue
        default = f.default if f.default is not dataclasses.MISSING else "required"
        rows.append((f.name, repr(default), lim.describe(), lim.unit, lim.doc))
    return rows


def undeclared(cls: Any) -> Iterable[str]:
    """Fields of `cls` that declare no `Limit` (a test asserts every model declares all)."""
    return [f.name for f in dataclasses.fields(cls) if "limit" not in f.metadata]
