"""What the engines keep in a scene, as data: a JSON codec for their configurations (numbers,
text, lists, dicts, numpy arrays, and this package's own objects by their fields), that never
runs code when it reads.

A scene file is data a user may get from anyone; pickle, which this replaces, runs whatever a
crafted file asks when it is read. Here an object of this package is written as its class's
dotted name and its fields (``__dict__``, dataclass fields or ``__slots__``) and read back by
making an instance without calling anything of it (``cls.__new__`` then the fields set), for
classes of ``yade_electro`` only; anything else (a function, a foreign object) cannot be
written (:class:`TypeError` naming it) and an unknown class name cannot be read
(:class:`ValueError`). numpy arrays go as their dtype, shape and raw bytes in base64 (object
arrays are refused).

Units: none.
"""
from __future__ import annotations

import base64
import dataclasses
import importlib
import json
import math
from types import MappingProxyType

import numpy as np

__all__ = ["dumps", "loads", "PACKAGE"]

#: the only package whose classes are read back
PACKAGE = "yade_electro"


def _name(cls) -> str:
    return f"{cls.__module__}.{cls.__qualname__}"


def _fields(obj) -> dict:
    if dataclasses.is_dataclass(obj):
        return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}
    out = dict(getattr(obj, "__dict__", {}))
    for cls in type(obj).__mro__:
        for slot in getattr(cls, "__slots__", ()):
            if slot != "__dict__" and hasattr(obj, slot):
                out[slot] = getattr(obj, slot)
    return out


def _encode(obj, path: str):
    if obj is None or isinstance(obj, (bool, str)):
        return obj
    if isinstance(obj, np.bool_):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        f = float(obj)
        return f if math.isfinite(f) else {"__float__": repr(f)}
    if isinstance(obj, np.ndarray):
        if obj.dtype.hasobject:
            raise TypeError(f"{path}: an array of Python objects cannot be kept as data")
        a = np.ascontiguousarray(obj)
        return {"__array__": a.dtype.str, "shape": list(a.shape), "data": base64.b64encode(a.tobytes()).decode("ascii")}
    if isinstance(obj, tuple) and hasattr(obj, "_fields"):        # a named tuple of this package
        return {"__object__": _class_name(type(obj), path), "fields": {k: _encode(v, f"{path}.{k}")
                                                                        for k, v in obj._asdict().items()}}
    if isinstance(obj, (list, tuple)):
        items = [_encode(v, f"{path}[{k}]") for k, v in enumerate(obj)]
        return items if isinstance(obj, list) else {"__tuple__": items}
    if isinstance(obj, (set, frozenset)):
        return {"__set__": [_encode(v, f"{path}{{}}") for v in sorted(obj, key=repr)]}
    if isinstance(obj, (dict, MappingProxyType)):
        if all(isinstance(k, str) for k in obj):
            if any(k.startswith("__") for k in obj):
                return {"__items__": [[k, _encode(v, f"{path}[{k!r}]")] for k, v in obj.items()]}
            return {k: _encode(v, f"{path}[{k!r}]") for k, v in obj.items()}
        return {"__items__": [[_encode(k, f"{path} key"), _encode(v, f"{path}[{k!r}]")] for k, v in obj.items()]}
    if isinstance(obj, type) or callable(obj) and not hasattr(obj, "__dict__") and not hasattr(obj, "__slots__"):
        raise TypeError(f"{path}: {obj!r} is code, not data")
    return {"__object__": _class_name(type(obj), path),
            "fields": {k: _encode(v, f"{path}.{k}") for k, v in _fields(obj).items()}}


def _class_name(cls, path: str) -> str:
    name = _name(cls)
    if not name.startswith(PACKAGE + ".") or "<" in name:
        raise TypeError(f"{path}: a {name} cannot be kept as data (only numbers, text, lists, dicts, arrays and "
                        f"{PACKAGE}'s own objects can)")
    return name


def _class(name: str):
    if not isinstance(name, str) or not name.startswith(PACKAGE + "."):
        raise ValueError(f"a kept object of class {name!r}: only {PACKAGE}'s classes are read")
    module, _, qual = name.rpartition(".")
    while module:                                 # a nested class: the module is a prefix
        try:
            mod = importlib.import_module(module)
            break
        except ImportError:
            module, _, outer = module.rpartition(".")
            qual = f"{outer}.{qual}"
    else:
        raise ValueError(f"a kept object of class {name!r}: no such module")
    obj = mod
    for part in qual.split("."):
        obj = getattr(obj, part, None)
    if not isinstance(obj, type) or not _name(obj) == name:
        raise ValueError(f"a kept object of class {name!r}: no such class")
    return obj


def _decode(obj):
    if isinstance(obj, list):
        return [_decode(v) for v in obj]
    if not isinstance(obj, dict):
        return obj
    if "__float__" in obj:
        return float(obj["__float__"])
    if "__array__" in obj:
        dtype = np.dtype(obj["__array__"])
        if dtype.hasobject:
            raise ValueError("a kept array of Python objects is not read")
        return np.frombuffer(base64.b64decode(obj["data"]), dtype=dtype).reshape(obj["shape"]).copy()
    if "__tuple__" in obj:
        return tuple(_decode(v) for v in obj["__tuple__"])
    if "__set__" in obj:
        return {_decode(v) for v in obj["__set__"]}
    if "__items__" in obj:
        return {_hashable(_decode(k)): _decode(v) for k, v in obj["__items__"]}
    if "__object__" in obj:
        cls = _class(obj["__object__"])
        fields = {k: _decode(v) for k, v in obj["fields"].items()}
        if issubclass(cls, tuple) and hasattr(cls, "_fields"):
            return cls(**fields)
        inst = cls.__new__(cls)
        for k, v in fields.items():
            object.__setattr__(inst, k, v)
        return inst
    return {k: _decode(v) for k, v in obj.items()}


def _hashable(k):
    return tuple(_hashable(v) for v in k) if isinstance(k, list) else k


def dumps(obj) -> str:
    """``obj`` as JSON text (see the module doc); TypeError naming the part that is not data."""
    return json.dumps(_encode(obj, "the value"), allow_nan=False, separators=(",", ":"))


def loads(text: str):
    """The value :func:`dumps` wrote; ValueError for text that is not such data."""
    try:
        data = json.loads(text)
    except (ValueError, RecursionError) as exc:
        raise ValueError(f"kept data that is not JSON ({exc})") from None
    return _decode(data)
