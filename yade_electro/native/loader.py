"""Loading the compiled kernels, which are built when the package is installed (``setup.py``):
each ``<name>.cpp`` here is the shared library ``_<name>.<extension suffix>`` beside it, loaded
with ctypes; the CGAL Delaunay helper is the program ``delaunay_cgal``. Nothing is compiled at
run time, and no compiler is needed.
"""
from __future__ import annotations

import ctypes
import importlib.machinery
from pathlib import Path

__all__ = ["HERE", "NativeError", "library_path", "helper_path", "shared_function"]

#: the folder of the kernels' sources and builds
HERE = Path(__file__).resolve().parent

_REINSTALL = ("reinstall yade-electro so that its kernels are built (`make install`, or `pip install -e .` in the "
              "checkout; it needs g++ and libeigen3-dev at install time)")


class NativeError(RuntimeError):
    """A compiled kernel is not built (the package was not installed with them) or failed."""


def library_path(name: str) -> Path:
    """The built shared library of kernel ``name``; NativeError when it is not there."""
    for suffix in importlib.machinery.EXTENSION_SUFFIXES:
        path = HERE / f"_{name}{suffix}"
        if path.exists():
            return path
    raise NativeError(f"the compiled kernel {name!r} is not built in {HERE}: {_REINSTALL}")


def helper_path(name: str) -> Path:
    """The built helper program ``name``; NativeError when it is not there."""
    path = HERE / name
    if not path.exists():
        raise NativeError(f"the helper program {name!r} is not built in {HERE} (it is built at install when its "
                          "libraries are there)")
    return path


_LIBRARIES = {}


def shared_function(name: str, symbol: str, argtypes, restype):
    """The function ``symbol`` of kernel ``name``, loaded once with ctypes (NativeError, kept for
    later calls, when the kernel is not built)."""
    key = (name, symbol)
    if key not in _LIBRARIES:
        try:
            f = getattr(ctypes.CDLL(str(library_path(name))), symbol)
            f.argtypes, f.restype = argtypes, restype
            _LIBRARIES[key] = f
        except (NativeError, OSError, AttributeError) as exc:
            _LIBRARIES[key] = NativeError(f"{name}: {exc}")
    if isinstance(_LIBRARIES[key], Exception):
        raise _LIBRARIES[key]
    return _LIBRARIES[key]
