"""The BLAS thread limit of the solvers.

The solvers' work is sparse products (scipy, one thread) and vector reductions (dot, norm)
that numpy hands to OpenBLAS. Inside ``yade`` OpenBLAS runs one thread; in a plain
``python3`` on this 2-core machine it starts two, and the CG got 1.1-4x slower from the
threads' start-up on every short reduction (measured before this module; README *Scale*).
So importing :mod:`yade_electro.solvers.registry` holds OpenBLAS to ``YADE_ELECTRO_BLAS_THREADS``
threads (default 1) through OpenBLAS' own ``openblas_set_num_threads``, found in the
libraries this process has loaded (as threadpoolctl does). Set the variable to ``0`` to
leave OpenBLAS as it is.
"""
from __future__ import annotations

import ctypes
import os
from typing import Optional

__all__ = ["blas_library", "blas_threads", "limit_blas_threads", "apply_default_limit"]

_LIB = None


def blas_library() -> Optional[ctypes.CDLL]:
    """The loaded OpenBLAS (None when numpy uses another BLAS)."""
    global _LIB
    if _LIB is not None:
        return _LIB
    import numpy  # noqa: F401  (loads the BLAS)
    try:
        with open("/proc/self/maps") as fh:
            paths = {line.split()[-1] for line in fh if "openblas" in line.lower() and "/" in line}
    except OSError:
        return None
    for path in sorted(paths):
        try:
            lib = ctypes.CDLL(path)
            lib.openblas_set_num_threads
            lib.openblas_get_num_threads
        except (OSError, AttributeError):
            continue
        _LIB = lib
        return lib
    return None


def blas_threads() -> Optional[int]:
    """OpenBLAS' current thread count (None without OpenBLAS)."""
    lib = blas_library()
    return None if lib is None else int(lib.openblas_get_num_threads())


def limit_blas_threads(n: int) -> Optional[int]:
    """Set OpenBLAS to ``n`` threads; returns the previous count (None without OpenBLAS)."""
    n = int(n)
    if n < 1:
        raise ValueError(f"BLAS threads must be >= 1, got {n}")
    lib = blas_library()
    if lib is None:
        return None
    before = int(lib.openblas_get_num_threads())
    lib.openblas_set_num_threads(n)
    return before


def apply_default_limit() -> Optional[int]:
    """The limit of ``YADE_ELECTRO_BLAS_THREADS`` (default 1; 0: none). Returns the count set."""
    raw = os.environ.get("YADE_ELECTRO_BLAS_THREADS", "1")
    try:
        n = int(raw)
    except ValueError:
        raise ValueError(f"YADE_ELECTRO_BLAS_THREADS must be an integer (0: no limit), got {raw!r}") from None
    if n == 0:
        return None
    limit_blas_threads(n)
    return n
