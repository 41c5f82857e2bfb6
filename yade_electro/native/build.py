"""Building and loading the compiled helpers: g++ into the cache directory on first use, ctypes.

Units: none.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

__all__ = ["HERE", "NativeError", "cache_dir", "build", "shared_function"]

#: the folder of the C++ sources
HERE = Path(__file__).resolve().parent


class NativeError(RuntimeError):
    """A compiled helper could not be built or failed."""


def cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "yade-electro"


def build(src: Path, name: str, libs, shared: bool = False) -> Path:
    cache = cache_dir()
    cache.mkdir(parents=True, exist_ok=True)
    tag = hashlib.sha1(src.read_bytes()).hexdigest()[:12]        # the source's content, not its mtime
    exe = cache / (f"lib{name}_{tag}.so" if shared else f"{name}_{tag}")
    if exe.exists():
        return exe
    cxx = shutil.which("g++")
    if cxx is None:
        raise NativeError("g++ not found (apt-get install g++; `make install` does)")
    print(f"[yade-electro] building {name} (once, {'a few seconds' if shared else 'about 15 s'}) into {cache}",
          file=sys.stderr, flush=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{name}_", dir=str(cache))
    os.close(fd)
    cmd = [cxx, "-O2", "-std=c++17", "-DNDEBUG"] + (["-shared", "-fPIC"] if shared else []) + ["-o", tmp, str(src)] \
        + list(libs)
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        os.unlink(tmp)
        raise NativeError(f"building {name} failed:\n{' '.join(cmd)}\n{r.stderr[-2000:]}")
    os.chmod(tmp, 0o755)
    os.replace(tmp, exe)
    return exe


_LIBRARIES = {}


def shared_function(name: str, symbol: str, argtypes, restype, flags=()):
    """The function ``symbol`` of the shared library built from ``<name>.cpp``, loaded once
    with ctypes (raises :class:`NativeError`, kept for later calls, when it cannot be built)."""
    key = (name, symbol)
    if key not in _LIBRARIES:
        try:
            import ctypes
            lib = ctypes.CDLL(str(build(HERE / f"{name}.cpp", name, list(flags), shared=True)))
            f = getattr(lib, symbol)
            f.argtypes, f.restype = argtypes, restype
            _LIBRARIES[key] = f
        except (NativeError, OSError, AttributeError) as exc:
            _LIBRARIES[key] = NativeError(f"{name}: {exc}")
    if isinstance(_LIBRARIES[key], Exception):
        raise _LIBRARIES[key]
    return _LIBRARIES[key]
