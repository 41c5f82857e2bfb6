"""``solver='petsc'``: PETSc's CG + GAMG (through petsc4py), serial or distributed under MPI.

The network problems are assembled by numpy on every rank (the graph, conductances and the
reduced matrix are replicated); only the linear solve is distributed. Each rank hands PETSc
its block of rows of the same CSR matrix (PETSc's default ownership: contiguous blocks of
about n / size rows), PETSc iterates with the ranks working together, and the solution is
gathered onto every rank, so every rank writes the same values back to its bodies. This
pays when the solve dominates (large packings, many re-solves); the memory per rank is
not reduced (see docs/benchmarks.md for what a cluster user gets).

Run standalone with ``mpiexec -n 2 /usr/bin/python3 script.py``, or a YADE script with
``mpiexec -n 2 yade-electro -n -x script.py`` (every rank runs the same scene). Without
``mpiexec`` it runs on one rank (MPI singleton). As root OpenMPI wants
``--allow-run-as-root`` (or ``OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1``).

Stopping rule: the true residual ``||A x - b|| <= max(rtol ||b||, atol)``, as the other
solvers (KSP's unpreconditioned norm, with ``||b||`` as the reference also from a warm
start). ``update`` (same pattern, new values) sets the values in place and keeps GAMG's
prolongators (``PCGAMGSetReuseInterpolation``): only the Galerkin products are redone.

Needs Debian's ``python3-petsc4py`` (``make install`` installs it). Debian installs the
module under ``/usr/lib/petscdir/...`` and points to it through ``/usr/lib/petsc``, which
only the ``-dev`` package creates; :func:`import_petsc` finds it without that.
"""
from __future__ import annotations

import glob
import os
import subprocess
import sys
import time
from typing import Optional

import numpy as np
import scipy.sparse as sp

from ..core.errors import SolverError
from .base import Solver

__all__ = ["PETScSolver", "import_petsc", "petsc_available", "petsc4py_location", "check_preconditioner", "HYPRE_3D",
           "destroy_attributes"]

#: BoomerAMG's options for 3-D problems (hypre's advice for 3-D diffusion: HMIS coarsening,
#: ext+i interpolation, at most 4 entries per row of P, one level of aggressive coarsening)
HYPRE_3D = {"pc_hypre_type": "boomeramg", "pc_hypre_boomeramg_coarsen_type": "HMIS",
            "pc_hypre_boomeramg_interp_type": "ext+i", "pc_hypre_boomeramg_P_max": "4",
            "pc_hypre_boomeramg_agg_nl": "1", "pc_hypre_boomeramg_strong_threshold": "0.5"}

#: where Debian 12's python3-petsc4py puts the module (one directory per PETSc build)
DEBIAN_PETSC4PY = "/usr/lib/petscdir/petsc*/*-real/lib/python3/dist-packages"

_INSTALL_HINT = ("solver='petsc' needs petsc4py and mpi4py: `apt-get install python3-petsc4py python3-mpi4py` "
                 "(or `make install`), or use solver='cg-deflated'")


def petsc4py_location() -> Optional[str]:
    """The directory that holds the ``petsc4py`` package, found without importing it (importing
    it outside ``mpiexec`` starts an MPI singleton); None when it is not installed."""
    import importlib.util
    spec = importlib.util.find_spec("petsc4py")
    if spec is not None and spec.origin:
        return os.path.dirname(os.path.dirname(spec.origin))
    for path in sorted(glob.glob(DEBIAN_PETSC4PY), reverse=True):
        if os.path.isdir(os.path.join(path, "petsc4py")):
            return path
    return None


def import_petsc():
    """The ``PETSc`` module of petsc4py (initialised), importing it from Debian's directory
    when the ``/usr/lib/petsc`` link is missing. Raises :class:`SolverError` when absent.
    Outside ``mpiexec`` the MPI singleton it starts is kept off the network
    (:func:`~yade_electro.core.mpi_network.quiet_singleton`)."""
    from ..core.mpi_network import quiet_singleton, under_mpiexec
    quiet_singleton()
    started = sys.modules.get("petsc4py") is not None and "petsc4py.PETSc" in sys.modules
    if not started and not under_mpiexec():       # (once: MPI is up after the first import)
        _probe_mpi_start()
    try:
        from petsc4py import PETSc
        return PETSc
    except ImportError:
        pass
    for path in sorted(glob.glob(DEBIAN_PETSC4PY), reverse=True):
        if os.path.isdir(os.path.join(path, "petsc4py")):
            if path not in sys.path:
                sys.path.append(path)
            os.environ.setdefault("PETSC_DIR", os.path.dirname(os.path.dirname(os.path.dirname(path))))
            try:
                import petsc4py
                petsc4py.init([])              # no command-line options (YADE's argv is not PETSc's)
                from petsc4py import PETSc
                return PETSc
            except ImportError as exc:
                raise SolverError(f"petsc4py found in {path} but it does not import ({exc}); "
                                  + _INSTALL_HINT) from None
    raise SolverError(_INSTALL_HINT)


def _probe_mpi_start():
    """SolverError saying what happened when Open MPI cannot start in a process of this
    environment: its ``MPI_Init`` would abort the whole program (YADE included) with no Python
    error. Tried once in a child process first (about 0.3 s)."""
    path = petsc4py_location()
    if path is None:
        return                                  # the import below says petsc4py is missing
    code = (f"import sys; sys.path.append({path!r}); import petsc4py; petsc4py.init([]); "
            "from petsc4py import PETSc; print('MPI-OK', PETSc.COMM_WORLD.getSize())")
    try:
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                           stdin=subprocess.DEVNULL)
    except (OSError, subprocess.SubprocessError) as exc:
        raise SolverError(f"solver='petsc': could not try starting Open MPI ({exc})") from None
    if r.returncode != 0 or "MPI-OK" not in r.stdout:
        said = [ln.strip() for ln in (r.stderr + r.stdout).splitlines() if ln.strip() and not ln.startswith("---")]
        raise SolverError("solver='petsc': Open MPI cannot start in this environment, and starting it here would "
                          "abort the whole program without a Python error. It said: " + " | ".join(said[-6:])
                          + ". Use a solver without MPI (solver='auto'), or fix the MPI environment (a network "
                          "interface, OMPI_MCA_* settings) and run under mpiexec")


def check_preconditioner(preconditioner: str):
    """The PETSc module, or SolverError when petsc4py or (for 'hypre') PETSc's hypre is missing."""
    PETSc = import_petsc()
    if preconditioner == "hypre" and not PETSc.Sys.hasExternalPackage("hypre"):
        raise SolverError("the 'hypre' preconditioner needs PETSc built with hypre (Debian's libpetsc-real3.18 has "
                          "it); use solver='petsc' (GAMG or our deflation) or 'cg-deflated'")
    return PETSc


def petsc_available() -> bool:
    """True when :func:`import_petsc` works."""
    try:
        import_petsc()
        return True
    except SolverError:
        return False


def destroy_attributes(owner, names) -> None:
    """Destroy the PETSc objects held in the attributes ``names`` of ``owner`` and set them to
    None (collective for parallel objects: every rank calls it at the same point). petsc4py
    3.18 does not free objects of a parallel communicator (COMM_WORLD, even of one rank) when
    Python drops them; it defers them to a collective clean-up, so objects that are replaced
    must be destroyed."""
    for name in names:
        obj = getattr(owner, name, None)
        if obj is not None:
            obj.destroy()
            setattr(owner, name, None)


class PETScSolver(Solver):
    """CG preconditioned by PETSc's algebraic multigrid (GAMG, smoothed aggregation), on
    ``comm`` (default ``PETSc.COMM_WORLD``); see the module doc.

    Parameters
    ----------
    rtol : float
        Stop when ||A x - b|| <= rtol ||b|| (default 1e-10).
    maxiter : int, optional
        Default 10 n.
    preconditioner : {'gamg', 'hypre', 'jacobi', 'none'}
        GAMG by default; BoomerAMG with the 3-D options :data:`HYPRE_3D`; Jacobi to compare
        with ``'cg'``.
    comm : petsc4py communicator, optional
        ``PETSc.COMM_WORLD`` by default (all ranks of ``mpiexec``); ``PETSc.COMM_SELF`` for a
        rank-local solve.
    options : dict, optional
        Extra PETSc options for this solver's prefix (``ye_``), e.g.
        ``{"pc_gamg_threshold": 0.02}``.
    """

    name = "petsc"

    def __init__(self, rtol: float = 1e-10, maxiter: Optional[int] = None, preconditioner: str = "gamg",
                 comm=None, options: Optional[dict] = None):
        if not (0 < rtol < 1):
            raise ValueError(f"rtol must be in (0, 1), got {rtol}")
        if preconditioner not in ("gamg", "hypre", "jacobi", "none"):
            raise ValueError(f"preconditioner must be 'gamg', 'hypre', 'jacobi' or 'none', got {preconditioner!r}")
        super().__init__()
        self.PETSc = check_preconditioner(preconditioner)
        self.comm = self.PETSc.COMM_WORLD if comm is None else comm
        self.rtol, self.maxiter, self.preconditioner = float(rtol), maxiter, preconditioner
        self.options = dict(options or {})

    @property
    def size(self) -> int:
        """Number of MPI ranks taking part in the solve."""
        return self.comm.getSize()

    @property
    def rank(self) -> int:
        return self.comm.getRank()

    # -- setup -------------------------------------------------------------------------------
    def _local_csr(self, A):
        lo, hi = self._range
        ip = A.indptr[lo:hi + 1]
        a, z = int(ip[0]), int(ip[-1])
        return ((ip - a).astype(self.PETSc.IntType), A.indices[a:z].astype(self.PETSc.IntType),
                np.ascontiguousarray(A.data[a:z], dtype=self.PETSc.ScalarType))

    def _release(self):
        """Free the PETSc objects of the last setup (every rank sets up together; see
        :func:`destroy_attributes`: measured 10 MB kept per setup at 200k unknowns)."""
        destroy_attributes(self, ("_ksp", "_M", "_x", "_b", "_scatter", "_xall"))

    def _setup(self, A):
        PETSc = self.PETSc
        self._release()
        n = A.shape[0]
        self._Acsr = A if sp.isspmatrix_csr(A) else sp.csr_matrix(A)
        self._Acsr.sort_indices()
        # PETSc's default split of n rows over the ranks
        layout = PETSc.Vec().createMPI((None, n), comm=self.comm)
        self._range = layout.getOwnershipRange()
        self._x, self._b = layout.duplicate(), layout
        ip, ix, v = self._local_csr(self._Acsr)
        nloc = self._range[1] - self._range[0]
        self._M = PETSc.Mat().createAIJ(size=((nloc, n), (nloc, n)), csr=(ip, ix, v), comm=self.comm)
        self._M.setOption(PETSc.Mat.Option.SPD, True)
        self._M.assemble()
        ksp = PETSc.KSP().create(comm=self.comm)
        ksp.setOptionsPrefix("ye_")
        opts = PETSc.Options()
        for k, val in self.options.items():
            opts["ye_" + k] = val
        ksp.setOperators(self._M)
        ksp.setType(PETSc.KSP.Type.CG)
        ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
        pc = ksp.getPC()
        pc.setType({"gamg": PETSc.PC.Type.GAMG, "hypre": PETSc.PC.Type.HYPRE, "jacobi": PETSc.PC.Type.JACOBI,
                    "none": PETSc.PC.Type.NONE}[self.preconditioner])
        if self.preconditioner == "hypre":
            for k, val in HYPRE_3D.items():
                if not opts.hasName("ye_" + k):
                    opts["ye_" + k] = val
        if self.preconditioner == "gamg":
            opts["ye_pc_gamg_type"] = opts.getString("ye_pc_gamg_type", "agg")
            opts["ye_pc_gamg_reuse_interpolation"] = "true"
        ksp.setFromOptions()
        ksp.setUp()
        self._ksp = ksp
        self._scatter, self._xall = PETSc.Scatter.toAll(self._x)

    def _update(self, A):
        """New values (same pattern) into PETSc's matrix, GAMG's interpolation kept."""
        ip, ix, v = self._local_csr(self._Acsr)
        self._M.setValuesCSR(ip, ix, v)
        self._M.assemble()
        self._ksp.setOperators(self._M)

    # -- solve -------------------------------------------------------------------------------
    def solve(self, A, b, x0=None, atol: float = 0.0):
        """Solve ``A x = b`` from ``x0`` (every rank passes the same full vectors and gets the
        full solution)."""
        fresh = self._ensure_setup(A)
        b = np.asarray(b, dtype=float)
        n = b.shape[0]
        if n != A.shape[0]:
            raise ValueError(f"b has {n} entries for a {A.shape[0]}-row matrix")
        lo, hi = self._range
        nb = float(np.linalg.norm(b))
        t = time.perf_counter()
        self._b.setArray(b[lo:hi])
        if x0 is not None:
            self._x.setArray(np.asarray(x0, dtype=float)[lo:hi])
        else:
            self._x.set(0.0)
        ksp = self._ksp
        ksp.setInitialGuessNonzero(x0 is not None)
        # absolute tolerance from ||b||: the same rule from a cold or a warm start
        ksp.setTolerances(rtol=1e-300, atol=max(self.rtol * nb, atol, 1e-300),
                          max_it=self.maxiter or 10 * n + 10)
        if nb == 0.0 and atol == 0.0:
            x = np.zeros(n)
            return x, {"solver": self.name, "iterations": 0, "residual": 0.0, "setup": fresh,
                       "setup_time": self.setup_time, "iteration_time": 0.0, "ranks": self.size}
        ksp.solve(self._b, self._x)
        reason, it = ksp.getConvergedReason(), ksp.getIterationNumber()
        self._scatter.scatter(self._x, self._xall)          # insert, forward: all of x on every rank
        x = self._xall.getArray(readonly=True).copy()
        if not np.all(np.isfinite(x)):
            raise SolverError("the PETSc solve produced non-finite values (singular matrix?)")
        res = float(np.linalg.norm(self._Acsr @ x - b))
        rel = res / nb if nb > 0 else res
        if reason < 0 or res > 10 * max(self.rtol * nb, atol):
            raise SolverError(f"petsc (CG + {self.preconditioner}) did not converge: KSP reason {reason}, "
                              f"relative residual {rel:.3e} > rtol {self.rtol:g} after {it} iterations; "
                              "raise maxiter or use solver='direct'")
        return x, {"solver": self.name, "iterations": int(it), "residual": rel, "setup": fresh,
                   "setup_time": self.setup_time, "iteration_time": time.perf_counter() - t,
                   "ranks": self.size}
