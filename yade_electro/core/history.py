"""Histories: rows of figures kept in memory and written to a CSV file as they come.

Each row is appended and flushed at once, so a crash loses nothing written so far. The file
is opened per row; when that fails (disk full, directory removed, permissions) the history
warns once, keeps every row in memory and keeps the simulation running; at the next row that
can be written it recreates the directory and rewrites the whole file from memory, so the CSV
is complete again.

Modes (``mode=``): ``'w'`` starts a new file and says so (a warning) when it replaces an
existing one; ``'a'`` appends to an existing file whose header matches (a resumed run; the
rows already there are read back into memory); ``'x'`` refuses an existing file.
"""
from __future__ import annotations

import csv
import logging
import os
import warnings
from typing import List, Mapping, Optional

import numpy as np

__all__ = ["History"]

log = logging.getLogger(__name__)


_NAN = float("nan")


def _fmt(v):
    if isinstance(v, float):
        return repr(v)
    return v


def _parse(v: str):
    try:
        f = float(v)
    except ValueError:
        return v
    if f.is_integer() and "." not in v and "e" not in v.lower() and "inf" not in v.lower() and "nan" not in v.lower():
        return int(f)
    return f


class History:
    """Rows of figures in memory, and in a CSV file when ``path`` is given.

    The columns are the first row's keys; a later row with a key not seen yet adds its column
    (the file is written again with the wider header, earlier rows empty there: ``nan``), and
    a row without a column's key has ``nan`` there (a steady solve's row after time steps,
    or the other way round).

    Parameters
    ----------
    path : str, optional
    mode : {'w', 'a', 'x'}
        See the module doc.
    """

    def __init__(self, path: Optional[str] = None, mode: str = "w"):
        if mode not in ("w", "a", "x"):
            raise ValueError(f"history mode must be 'w' (new file), 'a' (append) or 'x' (refuse an existing "
                             f"file), got {mode!r}")
        self.path = None if path is None else os.fspath(path)
        self.mode = mode
        self.rows: List[dict] = []
        self._fields: Optional[List[str]] = None
        self._file_ok = True          # False after a failed write: rewrite everything when it works again
        self._written = 0             # rows of self.rows that are in the file
        self._widened = False         # a row added columns: rewrite the file with the wider header
        if self.path:
            exists = os.path.exists(self.path) and os.path.getsize(self.path) > 0
            if mode == "x" and exists:
                raise FileExistsError(f"history file {self.path!r} exists; give another path, or "
                                      "history_mode='w' to replace it or 'a' to append to it")
            if mode == "a" and exists:
                self._read_back()
            else:
                if mode == "w" and exists:
                    warnings.warn(f"history file {self.path!r} exists and is replaced (history_mode='a' appends "
                                  "to it, 'x' refuses it)", stacklevel=3)
                self._try(lambda: self._ensure_dir() or open(self.path, "w").close())

    # -- file ----------------------------------------------------------------------------------
    def _ensure_dir(self):
        d = os.path.dirname(os.path.abspath(self.path))
        os.makedirs(d, exist_ok=True)

    def _read_back(self):
        rows = []
        with open(self.path, newline="") as fh:
            reader = csv.reader(fh)
            try:
                for r in reader:
                    rows.append(r)
            except (csv.Error, UnicodeDecodeError) as exc:
                raise ValueError(f"history file {self.path!r}, line {reader.line_num}: {exc}. It is not a history "
                                 "this package wrote, or it is damaged: give another history path, or "
                                 "history_mode='w' to replace it") from None
        if not rows:
            return
        self._fields = rows[0]
        skipped = []
        for n, r in enumerate(rows[1:], start=2):
            if len(r) != len(self._fields):
                skipped.append(n)
                continue
            self.rows.append({k: _parse(v) for k, v in zip(self._fields, r)})
        if skipped:
            warnings.warn(f"history file {self.path!r}: rows {skipped[:10]} do not have the header's "
                          f"{len(self._fields)} fields (a write cut short?) and are left out", stacklevel=4)
        self._written = len(self.rows)

    def _try(self, fn) -> bool:
        try:
            fn()
        except OSError as exc:
            if self._file_ok:
                warnings.warn(f"cannot write the history file {self.path!r} ({exc}); the rows are kept in memory "
                              "(History.rows) and the file is rewritten in full once it can be written again",
                              RuntimeWarning, stacklevel=4)
            self._file_ok = False
            return False
        return True

    def _write_pending(self):
        def rewrite():
            self._ensure_dir()
            with open(self.path, "w", newline="") as fh:
                w = csv.writer(fh)
                w.writerow(self._fields)
                for r in self.rows:
                    w.writerow([_fmt(r.get(k, _NAN)) for k in self._fields])

        def append():
            with open(self.path, "a", newline="") as fh:
                w = csv.writer(fh)
                if self._written == 0 and fh.tell() == 0:
                    w.writerow(self._fields)
                for r in self.rows[self._written:]:
                    w.writerow([_fmt(r.get(k, _NAN)) for k in self._fields])
        if not self._file_ok or self._widened or not os.path.exists(self.path):
            ok = self._try(rewrite)
        else:
            ok = self._try(append)
        if ok:
            if not self._file_ok:
                log.warning("history file %s written again (%d rows)", self.path, len(self.rows))
            self._file_ok, self._widened = True, False
            self._written = len(self.rows)

    # -- rows ----------------------------------------------------------------------------------
    @property
    def columns(self) -> Optional[List[str]]:
        return None if self._fields is None else list(self._fields)

    def append(self, row: Mapping[str, float]):
        """Add a row (and write it to the file)."""
        row = dict(row)
        if self._fields is None:
            self._fields = list(row)
        else:
            new = [k for k in row if k not in self._fields]
            if new:                       # a wider header: the whole file is written again
                self._fields = self._fields + new
                self._widened = True
        self.rows.append(row)
        if self.path:
            self._write_pending()

    def truncate(self, n_rows: int) -> List[dict]:
        """Keep the first ``n_rows`` rows (in memory and in the file); returns the rows removed."""
        removed = self.rows[n_rows:]
        self.rows = self.rows[:n_rows]
        if self.path and removed:
            self._written = 0
            self._file_ok = False        # rewrite the file from memory
            if self._fields is not None:
                self._write_pending()
        return removed

    def __len__(self):
        return len(self.rows)

    def column(self, name: str) -> np.ndarray:
        return np.array([r.get(name, _NAN) for r in self.rows])

    def to_dataframe(self):
        """The history as a pandas DataFrame (pandas is imported only here)."""
        import pandas as pd
        return pd.DataFrame(self.rows, columns=self._fields)
