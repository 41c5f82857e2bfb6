"""``preconditioner='auto'`` of a partitioned solve: the run's own solves measure the candidates
and the fastest is kept.

Which preconditioner is fastest depends on the system, the size and the ranks: on this
project's benches (``bench/bench_peers.py``, partitioned lines) our deflation is ahead on one
rank and at most sizes, GAMG's kept hierarchy 4-20 % ahead of it re-solving in some 2-3 rank
rows, and BoomerAMG the fastest of all on the 1M-unknown Voronoi rod on 2 ranks. :class:`MeasuredChoice` therefore tries each candidate on the solves the run makes anyway:
``trial_solves`` solves each (the first builds the candidate's setup; the last is a re-solve on
the kept setup, the cost every later call pays), timed from the values' update to the end of the
solve on the slowest rank (a collective maximum, so every rank picks the same). It then keeps
the candidate whose last trial was fastest and frees the others. Every trial solve is a full
solve to the tolerance: the answers do not depend on the choice.

Units: seconds. The object has the interface the partitioned physics use
(:meth:`set_values`, :meth:`solve`, :meth:`destroy`).
"""
from __future__ import annotations

import logging
import time
from typing import Callable, Optional, Sequence

__all__ = ["MeasuredChoice", "AUTO_CANDIDATES", "auto_candidates"]

log = logging.getLogger(__name__)

#: what ``'auto'`` tries, in this order (the default first), BoomerAMG when PETSc has hypre
#: (:func:`auto_candidates`): on the 1M-unknown Voronoi rod on 2 ranks it is the fastest of all
AUTO_CANDIDATES = ("deflation", "gamg", "hypre")


def auto_candidates() -> tuple:
    """:data:`AUTO_CANDIDATES` less 'hypre' when PETSc is built without it."""
    from .petsc import import_petsc
    if import_petsc().Sys.hasExternalPackage("hypre"):
        return AUTO_CANDIDATES
    return tuple(c for c in AUTO_CANDIDATES if c != "hypre")


class MeasuredChoice:
    """See the module doc.

    Parameters
    ----------
    make : callable
        ``make(name)`` -> a :class:`~yade_electro.solvers.partitioned.PartitionedSystem` with
        preconditioner ``name`` (collective).
    comm : mpi4py communicator
    candidates : names tried, in order (default :func:`auto_candidates`)
    trial_solves : int >= 2
        Solves per candidate (the first builds its setup).
    """

    def __init__(self, make: Callable[[str], object], comm, candidates: Optional[Sequence[str]] = None,
                 trial_solves: int = 2):
        if int(trial_solves) < 2:
            raise ValueError(f"trial_solves must be >= 2 (a cold solve, then a re-solve), got {trial_solves}")
        candidates = auto_candidates() if candidates is None else candidates
        if not candidates:
            raise ValueError("give at least one candidate preconditioner")
        self._make, self.comm = make, comm
        self.candidates, self.trial_solves = tuple(candidates), int(trial_solves)
        #: each candidate's trial times [s] (slowest rank), in order
        self.timings = {name: [] for name in self.candidates}
        #: the candidate kept, once the trials are over (None before)
        self.chosen: Optional[str] = None
        self._name = self.candidates[0]
        self.active = make(self._name)
        self._values, self._t0 = None, None

    @property
    def preconditioner(self) -> str:
        """The candidate solving now."""
        return self._name

    def set_values(self, data, exchange=None):
        """New CSR values (collective): given to the active candidate, kept for the next one."""
        self._values = (data, exchange)
        self._t0 = time.perf_counter()
        self.active.set_values(data, exchange)

    def _switch(self, name: str):
        self.active.destroy()
        self._name = name
        self.active = self._make(name)
        self._t0 = time.perf_counter()
        self.active.set_values(*self._values)

    def solve(self, b_owned, x0=None, atol: float = 0.0):
        """Solve with the active candidate (collective); during the trials, time it and move on
        to the next candidate or to the choice. Returns (x, info) with ``info['preconditioner']``."""
        t0 = self._t0 if self._t0 is not None else time.perf_counter()
        x, info = self.active.solve(b_owned, x0=x0, atol=atol)
        info = dict(info, preconditioner=self._name, chosen=self.chosen)
        if self.chosen is None:
            from mpi4py import MPI
            elapsed = self.comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
            times = self.timings[self._name]
            times.append(float(elapsed))
            if len(times) >= self.trial_solves:
                later = self.candidates[self.candidates.index(self._name) + 1:]
                if later:
                    self._switch(later[0])
                else:
                    self.chosen = min(self.candidates, key=lambda n: self.timings[n][-1])
                    log.info("partitioned solve: %s kept (re-solve %s)", self.chosen,
                             ", ".join(f"{n} {self.timings[n][-1]:.3g} s" for n in self.candidates))
                    if self.chosen != self._name:
                        self._switch(self.chosen)
        self._t0 = None
        return x, info

    def destroy(self):
        """Free the active candidate's PETSc objects (collective)."""
        self.active.destroy()
