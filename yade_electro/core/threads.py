"""The BLAS thread limit of the solvers, through threadpoolctl.

The solvers' work is sparse products (scipy, one thread) and vector reductions (dot, norm)
that numpy hands to the BLAS. Inside ``yade`` OpenBLAS runs one thread; in a plain
``python3`` on a 2-core machine it starts two, and the CG got 1.1-4x slower from the
threads' start-up on every short reduction (``bench/bench_threads.py`` measures it). So
importing :mod:`yade_electro.solvers` holds the BLAS to ``YADE_ELECTRO_BLAS_THREADS``
threads (default 1). Set the variable to ``0`` to leave the BLAS as it is.
"""
from __future__ import annotations

import os
from typing import Optional

from threadpoolctl import threadpool_info, threadpool_limits

__all__ = ["blas_threads", "limit_blas_threads", "apply_default_limit"]


def blas_threads() -> Optional[int]:
    """The BLAS' current thread count (None when no BLAS is loaded)."""
    counts = [info["num_threads"] for info in threadpool_info() if info.get("user_api") == "blas"]
    return int(counts[0]) if counts else None


def limit_blas_threads(n: int) -> Optional[int]:
    """Set the BLAS to ``n`` threads; returns the previous count (None when no BLAS is loaded)."""
    n = int(n)
    if n < 1:
        raise ValueError(f"BLAS threads must be >= 1, got {n}")
    before = blas_threads()
    if before is not None:
        threadpool_limits(limits=n, user_api="blas")
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
    import numpy  # noqa: F401  (loads the BLAS)
    limit_blas_threads(n)
    return n
