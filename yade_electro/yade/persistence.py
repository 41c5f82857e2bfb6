"""An engine's configuration and state, kept in the scene itself so that ``O.save`` /
``O.load`` carry them.

YADE saves ``O.tags`` (a dict of strings) with the scene. Each engine keeps two tags (three
with ``overlap=True``):

* ``yade_electro:<label>:config``: everything needed to build the engine again (materials,
  law and its reference geometry, electrode and boundary-condition membership *by body id*,
  solver, options), as data (:mod:`yade_electro.core.codec`: JSON, arrays in base64, this
  package's objects by their fields; never pickle, which would run code a crafted scene file
  holds); written when the engine is built;
* ``yade_electro:<label>:state``: what changes every call (electrode values, thermal clock,
  energy ledger, fixed temperatures, the iteration and time of the last call, the number of
  history rows), JSON; written at every call (about 30 us);
* ``yade_electro:<label>:call``: with ``overlap=True``, the input of the call computed on the
  worker thread and not yet published (the same codec), which a loaded scene replays.

Tags an older version wrote with pickle are not read (a clear error says to build the engine
again).

Temperatures are in ``b.state.temp`` (YADE's ThermalState), which YADE saves itself.
"""
from __future__ import annotations

import json
from typing import Optional

from ..core import codec

__all__ = ["PREFIX", "config_key", "state_key", "call_key", "save_config", "load_config", "save_state", "load_state",
           "save_call", "load_call",
           "saved_labels", "forget", "add_container", "scene_container"]

PREFIX = "yade_electro"


def config_key(label: str) -> str:
    return f"{PREFIX}:{label}:config"


def state_key(label: str) -> str:
    return f"{PREFIX}:{label}:state"


def _tags(O):
    return O.tags


def _tag(O, key: str) -> Optional[str]:
    """The text of tag ``key``, or None when it is missing or emptied (:func:`forget`)."""
    tags = _tags(O)
    return tags[key] if key in tags.keys() and tags[key] else None


def _read(text: Optional[str], what: str):
    if text is None:
        return None
    try:
        return codec.loads(text)
    except ValueError as exc:
        raise ValueError(f"{what} in this scene cannot be read ({exc}): a scene saved by an older yade-electro "
                         "(which kept it in pickle, a format that can run code, no longer read) or damaged; build "
                         "the engine again instead of attaching it") from None


def save_config(O, label: str, config: dict) -> None:
    """Store an engine's configuration in the scene (as data; raises TypeError naming the part
    that is not data)."""
    try:
        text = codec.dumps(config)
    except TypeError as exc:
        raise TypeError(f"the configuration of engine {label!r} cannot be saved with the scene ({exc}); "
                        "give selectors, containers and options as plain data or YADE predicates") from None
    _tags(O)[config_key(label)] = text


def load_config(O, label: str) -> Optional[dict]:
    """The configuration saved under ``label``, or None."""
    return _read(_tag(O, config_key(label)), f"the saved configuration of engine {label!r}")


def save_state(O, label: str, state: dict) -> None:
    """Store an engine's changing state (JSON) in the scene."""
    _tags(O)[state_key(label)] = json.dumps(state)


def call_key(label: str) -> str:
    return f"{PREFIX}:{label}:call"


def save_call(O, label: str, call) -> None:
    """Store an overlapped engine's unpublished call (plain data) in the scene: a tag of its
    own, so the state's JSON stays small."""
    _tags(O)[call_key(label)] = codec.dumps(call)


def load_call(O, label: str):
    """The unpublished call saved under ``label``, or None."""
    return _read(_tag(O, call_key(label)), f"the unpublished call of engine {label!r}")


def load_state(O, label: str) -> Optional[dict]:
    """The state saved under ``label``, or None."""
    text = _tag(O, state_key(label))
    return None if text is None else json.loads(text)


def saved_labels(O) -> list:
    """Labels of the engines whose configuration the scene holds."""
    out = []
    tags = _tags(O)
    for k in tags.keys():
        parts = str(k).split(":")
        if len(parts) == 3 and parts[0] == PREFIX and parts[2] == "config" and tags[k]:
            out.append(parts[1])
    return sorted(out)


def forget(O, label: str) -> None:
    """Clear an engine's tags in the scene (YADE's tags cannot be deleted: they are emptied)."""
    tags = _tags(O)
    for key in (config_key(label), state_key(label), call_key(label)):
        if key in tags.keys():
            tags[key] = ""


CONTAINER_KEY = f"{PREFIX}:containers"


def add_container(O, shape, ids) -> None:
    """Record that the bodies ``ids`` were packed in ``shape`` (a Shape): what
    ``add_bonded_packing`` leaves in the scene for the engines (saved with it)."""
    tags = _tags(O)
    kept = []
    if CONTAINER_KEY in tags.keys() and tags[CONTAINER_KEY]:
        try:
            kept = list(codec.loads(tags[CONTAINER_KEY]))
        except ValueError:          # an older version's tag: started again
            kept = []
    ids = list(int(i) for i in ids)
    kept.append((shape, (min(ids), max(ids), len(ids)) if ids else (0, -1, 0)))
    tags[CONTAINER_KEY] = codec.dumps(kept)


def scene_container(O):
    """The container of the scene's packing when exactly one packing was added with one
    (``add_bonded_packing``), else None."""
    tags = _tags(O)
    if CONTAINER_KEY not in tags.keys() or not tags[CONTAINER_KEY]:
        return None
    try:
        kept = codec.loads(tags[CONTAINER_KEY])
    except ValueError:          # a tag this version cannot read: as if there were none
        return None
    return kept[0][0] if len(kept) == 1 else None
