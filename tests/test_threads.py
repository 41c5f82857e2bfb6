"""The solvers' BLAS thread limit: the BLAS (through threadpoolctl) is held to the count of
YADE_ELECTRO_BLAS_THREADS (default 1) once the solvers are imported."""
import pytest

from yade_electro.solvers import registry as solvers  # noqa: F401  (applies the default limit)
from yade_electro.core import threads as T


def test_solvers_hold_openblas_to_one_thread(monkeypatch):
    if T.blas_threads() is None:
        pytest.skip("no BLAS loaded here")
    assert T.blas_threads() == 1
    before = T.limit_blas_threads(2)
    assert before == 1 and T.blas_threads() == 2
    monkeypatch.setenv("YADE_ELECTRO_BLAS_THREADS", "0")
    assert T.apply_default_limit() is None and T.blas_threads() == 2        # 0: left alone
    monkeypatch.setenv("YADE_ELECTRO_BLAS_THREADS", "1")
    assert T.apply_default_limit() == 1 and T.blas_threads() == 1
    monkeypatch.setenv("YADE_ELECTRO_BLAS_THREADS", "two")
    with pytest.raises(ValueError, match="must be an integer"):
        T.apply_default_limit()
    with pytest.raises(ValueError, match=">= 1"):
        T.limit_blas_threads(0)
