"""The overlapped call of a heat-only granular engine (``Reader(overlap=True)``): its input as plain
data, the worker-thread marker, and the check that a core is free for the worker."""

from __future__ import annotations

import logging
import os
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Dict, NamedTuple, Optional

import numpy as np

from . import persistence
from .granular import Capture

__all__ = ["WORKER", "available_cores", "overlap_competes", "OverlapWork", "OverlappedCalls"]

log = logging.getLogger(__name__)


#: set on the worker thread while it computes an overlapped call
WORKER = threading.local()


def available_cores() -> int:
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def overlap_competes(yade_threads: int, cores: int) -> Optional[str]:
    """The warning for ``overlap=True`` when YADE's threads leave no core to the worker
    (None when one is free): on the drum with YADE on both cores of a 2-core machine, the
    overlapped engine took 26 % of the wall time against 22 % without overlap."""
    if yade_threads < cores:
        return None
    return (f"overlap=True: YADE runs {yade_threads} thread(s) on {cores} core(s), so the engine's worker thread "
            "competes with YADE's own threads; measured on the drum with YADE on both cores of a 2-core machine, "
            "it was slower than overlap=False (26 % of the wall time against 22 %). "
            + (f"Leave a core free (yade -j {cores - 1}) or use overlap=False" if cores > 1
               else "With one core, use overlap=False"))


class OverlapWork(NamedTuple):
    """An overlapped call's input: what it read from YADE, its thermal step [s], the set
    temperatures {body id: K} it applies, its iteration and time [s] (plain data: it pickles
    into the scene's state, so a loaded scene replays it)."""

    capture: Capture
    dt: float
    pending: Dict[int, float]
    iteration: int
    mech_time: float

    @classmethod
    def saved(cls, data) -> "OverlapWork":
        """The call of ``tuple(work)`` as :func:`persistence.load_call` gives it back."""
        capture, dt, pending, iteration, mech_time = data
        return cls(Capture(*capture), float(dt), dict(pending or {}), int(iteration), float(mech_time))


class OverlappedCalls:
    """The overlapped calls of a heat-only granular engine (``Reader(overlap=True)``), mixed into
    :class:`~yade_electro.yade.ElectroThermalEngine`: a call reads the scene and hands the numpy
    work (Verlet lists, conductances, the heat step, the history row) to a worker thread, and
    the next call (or :meth:`sync`) publishes it."""

    #: the call computed on the worker thread and not yet published (overlap=True)
    _inflight = None
    overlap = False

    def sync(self) -> Optional[dict]:
        """With ``overlap=True``: wait for the last call's work on the worker thread and publish
        it (temperatures to ``b.state.temp``, ``yade.plot``); returns its history row (None
        when nothing was pending). A worker's error is raised here. Without overlap: nothing."""
        return self._publish_inflight(save=True)

    def _publish_inflight(self, save: bool) -> Optional[dict]:
        if self._inflight is None or getattr(WORKER, "active", False):
            return None
        future, bodies = self._inflight
        self._inflight = None
        try:
            out, temperatures = future.result()
        except Exception as exc:
            self.error = exc
            log.error("yade-electro engine %r failed in its overlapped call: %s: %s", self.label,
                      type(exc).__name__, exc)
            raise
        self._publish(bodies, out, temperatures)
        if save:
            self._save_state()
        return out

    def _publish(self, bodies, out, temperatures):
        """An overlapped call's results to YADE: temperatures [K] to ``bodies``, its row to
        ``yade.plot`` (the worker already wrote it to the history)."""
        self._temperature_writer.write(bodies, temperatures)
        if self.plot:
            self._plot_row(out)

    def _drop_inflight(self):
        """Wait for a pending overlapped call and discard it (its scene was replaced)."""
        if self._inflight is not None:
            future, _ = self._inflight
            self._inflight = None
            future.exception()

    def _executor(self) -> ThreadPoolExecutor:
        if getattr(self, "_pool", None) is None:
            self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix=f"yade-electro-{self.label}")
        return self._pool

    def remove(self):
        """Publish a pending overlapped call, then as ``EngineBase.remove``."""
        try:
            self.sync()
        finally:
            super().remove()
            if getattr(self, "_pool", None) is not None:
                self._pool.shutdown(wait=True)
                self._pool = None

    def _step_overlapped(self):
        """One call with ``overlap=True``: publish the previous call, read the scene, save the
        state (the published one, plus this call's input), hand the rest to the worker."""
        if self._resumed_work is not None:          # a loaded scene's call that was not published
            work, self._resumed_work = self._resumed_work, None
            self._resume_work(work)
        self._publish_inflight(save=False)         # the state saved below covers it
        state = self._state_dict()
        capture, dt = self.reader.capture(), self._call_dt()
        self._apply_materials()
        work = OverlapWork(capture, dt, self._pending_temperatures, int(self.O.iter), float(self.O.time))
        self._pending_temperatures = {}
        self._last_time = work.mech_time
        state["pending"] = {}
        state["overlap_iter"] = work.iteration
        persistence.save_call(self.O, self.label, tuple(work))
        self._inflight_state = state
        self._inflight = (self._executor().submit(self._compute, work), self.reader.bodies)
        return None             # (_guarded saves the state)

    def _compute(self, work: "OverlapWork"):
        """The worker's part of an overlapped call: (history row, temperatures [K])."""
        WORKER.active = True
        try:
            graph = self.reader.advance(work.capture)
            row = self._heat_step(graph, work.dt, None, work.pending)
            out = self._row(work.iteration, work.mech_time, row, graph)
            self.history.append(out)
            return out, np.array(self._coupled.temperature, dtype=float)
        finally:
            WORKER.active = False

    def _resume_work(self, work: "OverlapWork"):
        """Compute and publish the saved unpublished call of a loaded scene (same spheres)."""
        if not np.array_equal(work.capture.ids, self.reader.graph.ids):
            log.warning("engine %r: the spheres changed between the load and the first call; the saved call of "
                        "iteration %d is not replayed (the next call integrates its interval)", self.label,
                        work.iteration)
            return
        self._publish(self._reader.bodies, *self._compute(work))
        self._last_time = work.mech_time
