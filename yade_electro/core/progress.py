"""Progress lines for long work: a line on stderr at most every ``PROGRESS_EVERY`` seconds,
with what is done, the time spent and an estimate of the time left.

Nothing is printed for work that ends within the first ``PROGRESS_EVERY`` seconds. Times in s.
"""
from __future__ import annotations

import sys
import time
from typing import Optional

__all__ = ["PROGRESS_EVERY", "Progress"]

#: seconds between progress lines
PROGRESS_EVERY = 10.0


class Progress:
    """Report a loop of ``total`` items of work under ``label``.

    ``update(done)`` prints ``[label] what: done of total in t s, about s left`` when
    ``every`` seconds (default :data:`PROGRESS_EVERY`, read when the report starts) have passed since the last line; ``waiting(note)`` does the same for a
    step whose share done is unknown (only the time spent is printed); ``done()`` prints a
    last line if anything was printed before.
    """

    def __init__(self, label: str, what: str, total: int = 0, every: Optional[float] = None, stream=None):
        self.label, self.what, self.total = label, what, int(total)
        self.every = float(PROGRESS_EVERY if every is None else every)
        self.stream = stream
        self.t0 = self.last = time.perf_counter()
        self.printed = 0

    def _print(self, text: str) -> None:
        print(f"[{self.label}] {text}", file=self.stream or sys.stderr, flush=True)
        self.printed += 1

    def _due(self) -> bool:
        now = time.perf_counter()
        if now - self.last < self.every:
            return False
        self.last = now
        return True

    @property
    def elapsed(self) -> float:
        return time.perf_counter() - self.t0

    def update(self, done: int) -> None:
        if not self._due():
            return
        t = self.elapsed
        left = t / done * (self.total - done) if done > 0 else float("nan")
        left_text = f"about {left:.0f} s left" if done > 0 else "time left unknown yet"
        self._print(f"{self.what}: {done:,} of {self.total:,} in {t:.0f} s, {left_text}")

    def waiting(self, note: str) -> None:
        if self._due():
            self._print(f"{self.what}: {note}, {self.elapsed:.0f} s so far")

    def done(self) -> None:
        if self.printed:
            self._print(f"{self.what}: done in {self.elapsed:.0f} s")
