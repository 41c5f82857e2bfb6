"""LIGGGHTS dump files (``dump custom`` of atoms, ``dump local`` of contacts) as pandas
DataFrames, one per snapshot.

A dump is a sequence of snapshots ``ITEM: TIMESTEP`` / ``ITEM: NUMBER OF ATOMS`` (or ``OF
ENTRIES``) / ``ITEM: BOX BOUNDS`` / ``ITEM: ATOMS <columns>`` (or ``ENTRIES``) followed by
the rows. Column names are LIGGGHTS' (``f_Temp``, ``c_contacts[4]``) unless ``columns``
renames them.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Sequence

import numpy as np

__all__ = ["DumpFrame", "read_dump", "read_dump_frames"]


@dataclass(frozen=True, eq=False)
class DumpFrame:
    """One snapshot: ``timestep``, ``kind`` ('atoms' or 'entries'), ``box`` (3, 2) [m] and
    ``data`` (a pandas DataFrame, one row per atom or contact)."""

    timestep: int
    kind: str
    box: np.ndarray
    data: object


def read_dump_frames(path, columns: Optional[Sequence[str]] = None) -> list:
    """Every snapshot of the dump at ``path`` as :class:`DumpFrame`, in file order.
    ``columns``: names replacing the dump's (same count). Integer-valued columns named
    ``id``, ``type``, ``id1``, ``id2`` become integers."""
    import pandas as pd
    path = Path(path)
    try:
        lines = path.read_text().splitlines()
    except FileNotFoundError:
        raise FileNotFoundError(f"LIGGGHTS dump {path} not found (did the run write it? check the deck's "
                                "dump command and the run's log)") from None
    frames, k = [], 0
    while k < len(lines):
        if not lines[k].startswith("ITEM: TIMESTEP"):
            if lines[k].strip():
                raise ValueError(f"{path}:{k + 1}: expected 'ITEM: TIMESTEP', got {lines[k][:60]!r}")
            k += 1
            continue
        if k + 8 >= len(lines):
            raise ValueError(f"{path}:{k + 1}: the snapshot's header is cut short ({len(lines) - k} of its 9 lines): "
                             "the run stopped while writing it")
        try:
            step = int(lines[k + 1])
            count = int(lines[k + 3])
            box = np.array([[float(v) for v in lines[k + 5 + d].split()[:2]] for d in range(3)])
        except ValueError as exc:
            raise ValueError(f"{path}:{k + 1}: a snapshot header that is not TIMESTEP / NUMBER / BOX BOUNDS "
                             f"({exc}): the file is damaged or not a LIGGGHTS dump") from None
        if box.shape != (3, 2) or count < 0:
            raise ValueError(f"{path}:{k + 1}: a snapshot header with {count} rows and box {box.tolist()}: the file is "
                             "damaged or not a LIGGGHTS dump")
        head = lines[k + 8].split()
        if head[:2] != ["ITEM:", head[1]] or head[1] not in ("ATOMS", "ENTRIES"):
            raise ValueError(f"{path}:{k + 9}: expected 'ITEM: ATOMS' or 'ITEM: ENTRIES', got {lines[k + 8][:60]!r}")
        names = head[2:]
        rows = lines[k + 9:k + 9 + count]
        if len(rows) != count:
            raise ValueError(f"{path}: snapshot at step {step} is cut short ({len(rows)} of {count} rows): the run "
                             "stopped while writing it")
        split = [r.split() for r in rows]
        short = [i for i, r in enumerate(split) if len(r) != len(names)]
        if short:
            i = short[0]
            raise ValueError(f"{path}:{k + 10 + i}: step {step} has a row of {len(split[i])} values for {len(names)} "
                             "columns (a line cut short: the run stopped while writing it?)")
        try:
            table = np.array(split, dtype=float) if count else np.zeros((0, len(names)))
        except ValueError as exc:
            raise ValueError(f"{path}: step {step} has a value that is not a number ({exc})") from None
        if columns is not None:
            if len(columns) != len(names):
                raise ValueError(f"{path}: {len(columns)} column names given for {len(names)} columns {names}")
            names = list(columns)
        df = pd.DataFrame(table, columns=names)
        for c in ("id", "type", "id1", "id2"):
            if c in df.columns:
                df[c] = df[c].astype(np.int64)
        frames.append(DumpFrame(timestep=step, kind=head[1].lower(), box=box, data=df))
        k += 9 + count
    return frames


def read_dump(path, columns: Optional[Sequence[str]] = None) -> dict:
    """``{timestep: DataFrame}`` of the dump at ``path`` (see :func:`read_dump_frames`)."""
    return {f.timestep: f.data for f in read_dump_frames(path, columns)}
