"""The overlapped call of a heat-only granular engine (``overlap=True``): its input as plain
data, the worker-thread marker, and the check that a core is free for the worker."""

from __future__ import annotations

import logging
import os
import threading
from typing import Dict, NamedTuple, Optional


from .granular import Capture

__all__ = ["WORKER", "available_cores", "overlap_competes", "OverlapWork"]

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
