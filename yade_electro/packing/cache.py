"""On-disk cache of placed packings: one ``.npz`` per parameter set, keyed by a hash of every
parameter of the generation (and of the sampled field of grid-sampled containers).

The cache lives in ``$YADE_ELECTRO_CACHE`` or ``~/.cache/yade_electro``. Files are written
atomically (a temporary file renamed into place), so parallel runs (``yade-batch``) never read
a half-written packing; an unreadable file is ignored and regenerated.
"""
from __future__ import annotations

import hashlib
import json
import logging
import os
from pathlib import Path
from typing import Optional

import numpy as np

from ..geometry.shapes import GridShape

__all__ = ["default_cache_dir", "grid_hash", "cache_key", "cache_path", "load_cached", "store"]

log = logging.getLogger(__name__)


def default_cache_dir() -> Path:
    """``$YADE_ELECTRO_CACHE`` or ``~/.cache/yade_electro``."""
    env = os.environ.get("YADE_ELECTRO_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "yade_electro"


def grid_hash(shape) -> str:
    """SHA-256 of the sampled fields of every :class:`GridShape` inside ``shape``."""
    h = hashlib.sha256()

    def walk(s):
        if isinstance(s, GridShape):
            h.update(np.ascontiguousarray(s.field).tobytes())
        for part in s.parts():
            walk(part)
    walk(shape)
    return h.hexdigest()


def cache_key(key: dict, shape) -> str:
    """The canonical JSON text of a parameter dict (with the grid hash of sampled shapes)."""
    key = dict(key)
    if "GridShape" in json.dumps(key.get("shape"), default=str):
        key["grid_hash"] = grid_hash(shape)
    return json.dumps(key, sort_keys=True, default=str)


def cache_path(blob: str, cache_dir=None) -> Optional[Path]:
    """Path of the cache file of a key blob (None when ``cache_dir`` is False)."""
    if cache_dir is False:
        return None
    digest = hashlib.sha256(blob.encode()).hexdigest()[:20]
    base = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    return base / f"packing-{digest}.npz"


def load_cached(path: Optional[Path]):
    """(centers, radii, meta) from a cache file, or None if there is none or it is unreadable."""
    if path is None or not path.exists():
        return None
    try:
        with np.load(path, allow_pickle=False) as z:
            return np.array(z["centers"]), np.array(z["radii"]), json.loads(str(z["meta"]))
    except Exception as exc:  # corrupt or old file: regenerate
        log.warning("ignoring unreadable cache file %s (%s)", path, exc)
        return None


def store(path: Optional[Path], centers, radii, meta: dict) -> None:
    """Write a packing to its cache file atomically; a failure is logged, never raised."""
    if path is None:
        return
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + f".{os.getpid()}.tmp.npz")
        np.savez(tmp, centers=centers, radii=radii, meta=json.dumps(meta))
        os.replace(tmp, path)
    except OSError as exc:
        log.warning("could not write the packing cache %s (%s)", path, exc)
