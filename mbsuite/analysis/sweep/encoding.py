"""What a sweep store holds: values as tagged plain JSON (`encode_value`/`decode_value`, equal in type and bits after
a round trip, nothing ever pickled), the canonical JSON and its SHA-256, and the key of a (function, point) pair."""

from __future__ import annotations

import functools
import hashlib
import json
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ...errors import MbsuiteError


class StoreError(MbsuiteError):
    """A sweep store cannot be used (not a store, old pickle format, unwritable, not UTF-8, a value it cannot hold)."""


class StoreWarning(UserWarning):
    """A record of a sweep store was not trusted (damaged, altered, torn); its point is recomputed."""


_TAG = "$"
_NUMERIC_KINDS = "biufcU"


def _enc_float(x: float) -> Any:
    return x if math.isfinite(x) else {_TAG: "float", "v": repr(x)}


def encode_value(obj: Any) -> Any:
    """A JSON value that `decode_value` turns back into `obj`, equal in type and bits (a NaN comes back as the
    plain NaN: its sign and payload are not kept). Holds None, bool, int, float
    (also nan/inf), complex, str, list, tuple, dict, numpy scalars and numeric/str arrays; anything else is a
    `StoreError` naming its type (nothing is ever pickled)."""
    if isinstance(obj, np.generic):  # before float and str: np.float64 and np.str_ are their subclasses
        if obj.dtype.kind not in _NUMERIC_KINDS:
            raise StoreError(f"cannot store a numpy scalar of dtype {obj.dtype}")
        return {_TAG: "scalar", "dtype": obj.dtype.str, "v": encode_value(obj.item())}
    if obj is None or isinstance(obj, bool | str):
        return obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        return _enc_float(float(obj))
    if isinstance(obj, complex):
        return {_TAG: "complex", "re": _enc_float(obj.real), "im": _enc_float(obj.imag)}
    if isinstance(obj, list):
        return [encode_value(v) for v in obj]
    if isinstance(obj, tuple):
        return {_TAG: "tuple", "items": [encode_value(v) for v in obj]}
    if isinstance(obj, dict):
        if all(isinstance(k, str) for k in obj) and _TAG not in obj:
            return {k: encode_value(v) for k, v in obj.items()}
        return {_TAG: "dict", "items": [[encode_value(k), encode_value(v)] for k, v in obj.items()]}
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind not in _NUMERIC_KINDS or obj.dtype.fields is not None:
            raise StoreError(f"cannot store a numpy array of dtype {obj.dtype} (numbers, booleans and str only)")
        return {_TAG: "ndarray", "dtype": obj.dtype.str, "shape": list(obj.shape),
                "data": [encode_value(v) for v in obj.ravel().tolist()]}
    raise StoreError(f"cannot store a value of type {type(obj).__module__}.{type(obj).__qualname__}; a stored "
                     "result or point holds None, bool, int, float, complex, str, list, tuple, dict and numpy "
                     "scalars/arrays of numbers")


def _dec_float(v: Any) -> float:
    if isinstance(v, dict) and v.get(_TAG) == "float" and v.get("v") in ("nan", "inf", "-inf"):
        return float(v["v"])
    if isinstance(v, int | float) and not isinstance(v, bool):
        return float(v)
    raise StoreError(f"bad float {v!r}")


def decode_value(obj: Any) -> Any:
    """The value `encode_value` encoded (a `StoreError` for anything it cannot have written)."""
    if obj is None or isinstance(obj, bool | int | str):
        return obj
    if isinstance(obj, float):
        return obj
    if isinstance(obj, list):
        return [decode_value(v) for v in obj]
    if not isinstance(obj, dict):
        raise StoreError(f"bad value of type {type(obj).__name__}")
    if _TAG not in obj:
        return {k: decode_value(v) for k, v in obj.items()}
    tag = obj[_TAG]
    try:
        if tag == "float":
            return _dec_float(obj)
        if tag == "complex":
            return complex(_dec_float(obj["re"]), _dec_float(obj["im"]))
        if tag == "tuple":
            return tuple(decode_value(v) for v in obj["items"])
        if tag == "dict":
            return {_hashable(decode_value(k)): decode_value(v) for k, v in obj["items"]}
        if tag in ("scalar", "ndarray"):
            dt = np.dtype(obj["dtype"])
            if dt.kind not in _NUMERIC_KINDS or dt.fields is not None:
                raise StoreError(f"bad dtype {obj['dtype']!r}")
            if tag == "scalar":
                return np.array(decode_value(obj["v"]), dtype=dt)[()]
            shape = tuple(int(s) for s in obj["shape"])
            data = [decode_value(v) for v in obj["data"]]
            if math.prod(shape) != len(data):
                raise StoreError(f"array shape {shape} does not hold {len(data)} values")
            return np.array(data, dtype=dt).reshape(shape)
    except (KeyError, TypeError, ValueError) as exc:
        raise StoreError(f"bad {tag!r} value: {exc}") from None
    raise StoreError(f"unknown tag {tag!r}")


def _hashable(k: Any) -> Any:
    try:
        hash(k)
    except TypeError:
        raise StoreError(f"unhashable dict key {k!r}") from None
    return k


def canonical(obj: Any) -> bytes:
    """JSON with sorted keys, no spaces, ASCII only: the bytes a checksum or key is computed over."""
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=False).encode()


def digest(obj: Any) -> str:
    """SHA-256 (hex) of the canonical JSON of `obj`."""
    return hashlib.sha256(canonical(obj)).hexdigest()


def fn_id(fn: Callable) -> str:
    """The qualified name of `fn` (with a partial's arguments): the function part of a point's key."""
    if isinstance(fn, functools.partial):
        args = canonical(encode_value([list(fn.args), dict(fn.keywords)])).decode()
        return f"partial({fn_id(fn.func)}, {args})"
    return f"{getattr(fn, '__module__', '?')}.{getattr(fn, '__qualname__', repr(fn))}"


def record_key(fn_name: str, point_enc: Any) -> str:
    """The key of an encoded point of the function named `fn_name` (see `point_key`)."""
    return digest({"fn": fn_name, "point": point_enc})


def point_key(fn: Callable, point: Any) -> str:
    """The store key of (function, point): SHA-256 of the canonical JSON of the function's qualified name (with a
    partial's arguments) and the encoded point. A closure's captured variables are not part of it: one store per
    study. `StoreError` for a point `encode_value` cannot hold."""
    return record_key(fn_id(fn), encode_value(point))
