"""Engines by label: unique labels, the PyRunner entry point, and re-attaching saved engines.

YADE's ``PyRunner`` runs a command string; ours is ``run('<label>')``, which finds the engine
registered under that label in this process. When there is none, because the scene was
loaded (``O.load``) in a new process, or the engine belongs to a scene that was replaced,
``run`` re-attaches the engine from the configuration and state the scene carries
(:mod:`.persistence`) and goes on. :func:`attach` does the same on request and returns the
engine, the documented one line after ``O.load``::

    O.load("run.yade.gz")
    engine = attach("electrothermal")       # then O.run(...) as before

Rules (checked when an engine is built, in the user's script):

* labels are Python identifiers and unique among the live engines of the scene: a default
  label that is taken is numbered (``electro_2``), an explicit one that is taken is refused;
  a label the scene already holds a saved engine under is refused (attach that one instead);
* two live engines may not write one history file;
* two live engines writing the same body attribute get a warning.

An engine is live while it is registered, not removed, and its scene is the current one.
"""
from __future__ import annotations

import logging
import os
import sys
import warnings
from typing import Dict, Optional

from . import persistence

__all__ = ["ENGINES", "RegisteredEngine", "get_engine", "run", "attach", "claim_label", "check_shared_outputs",
           "live_engines",
           "engine_type", "engine_class"]

log = logging.getLogger(__name__)

#: Engines by label, so that the PyRunner command (a string YADE evaluates) can reach them.
ENGINES: Dict[str, object] = {}

#: Engine classes by name, for re-attaching a saved configuration (filled by :func:`engine_type`).
_ENGINE_TYPES: Dict[str, type] = {}


class RegisteredEngine:
    """What every engine of ours does with YADE's PyRunner, this registry and the scene's tags:
    its runner (the loaded scene's, or a new one), removal, and re-attaching a saved one. A
    subclass has ``O``, ``label``, ``runner``, ``removed`` and ``_setup(**kwargs, label, O,
    _resume)``."""

    def _find_or_make_runner(self, iterPeriod: int):
        """The PyRunner labelled like the engine that a loaded scene keeps, or a new one that
        calls :func:`run` every ``iterPeriod`` iterations."""
        for e in self.O.engines:
            if type(e).__name__ == "PyRunner" and e.label == self.label:
                return e
        from .runtime import import_yade
        return import_yade().PyRunner(
            command=f"__import__('yade_electro.yade.registry', fromlist=['run']).run({self.label!r})",
            iterPeriod=int(iterPeriod), label=self.label)

    def remove(self):
        """Take the engine out of ``O.engines``, the registry and the scene's tags."""
        self.O.engines = [e for e in self.O.engines if e is not self.runner]
        if ENGINES.get(self.label) is self:
            ENGINES.pop(self.label, None)
        persistence.forget(self.O, self.label)
        self.removed = True

    @classmethod
    def resumed(cls, config: dict, label: str, O, overrides: Optional[dict] = None):
        """The engine ``config`` (what :mod:`.persistence` saved) describes, continuing the saved
        run on scene ``O``; ``overrides`` replace saved settings (internal names)."""
        engine = cls.__new__(cls)
        engine._setup(**{**dict(config["kwargs"]), **dict(overrides or {})}, label=label, O=O, _resume=config)
        return engine


def engine_type(cls: type) -> type:
    """Class decorator: register an engine class under its name, so that a scene saved with it
    re-attaches it after ``O.load``."""
    _ENGINE_TYPES[cls.__name__] = cls
    return cls


def engine_class(name: str) -> type:
    """The engine class of a saved configuration."""
    try:
        return _ENGINE_TYPES[name]
    except KeyError:
        raise KeyError(f"unknown saved engine type {name!r}; known: {sorted(_ENGINE_TYPES)}") from None


def live_engines(O=None) -> dict:
    """The registered engines whose scene is the current one."""
    return {k: e for k, e in ENGINES.items() if e.live}


def get_engine(label: str):
    """The engine registered under ``label``."""
    try:
        return ENGINES[label]
    except KeyError:
        raise KeyError(f"no yade-electro engine labelled {label!r}; have {sorted(ENGINES)} (after O.load, "
                       f"re-attach it: yade_electro.yade.attach({label!r}))") from None


def claim_label(label: Optional[str], default: str, O) -> str:
    """A unique label for a new engine (see the module doc); raises ValueError."""
    explicit = label is not None
    if explicit and (not isinstance(label, str) or not label.isidentifier()):
        raise ValueError(f"label must be a Python identifier (letters, digits, _), got {label!r}: YADE makes it "
                         "a name in the script's namespace")
    base = label if explicit else default
    taken = set(live_engines(O)) | set(persistence.saved_labels(O))
    if base not in taken:
        return base
    if base in persistence.saved_labels(O) and base not in live_engines(O):
        raise ValueError(f"this scene holds a saved yade-electro engine labelled {base!r} (it was loaded with "
                         f"O.load): re-attach it with yade_electro.yade.attach({base!r}), or give the new engine "
                         "another label=")
    if explicit:
        raise ValueError(f"an engine labelled {base!r} is already running in this scene; give another label= "
                         "or remove it first (engine.remove())")
    k = 2
    while f"{base}_{k}" in taken:
        k += 1
    log.info("label %r is taken: the new engine is labelled %r", base, f"{base}_{k}")
    return f"{base}_{k}"


def check_shared_outputs(engine) -> None:
    """Refuse a history file another live engine writes; warn about a shared write-back
    attribute."""
    for other in live_engines().values():
        if other is engine:
            continue
        p1, p2 = engine.history.path, other.history.path
        if p1 and p2 and os.path.abspath(p1) == os.path.abspath(p2):
            raise ValueError(f"engine {other.label!r} already writes the history file {p1!r}; give this engine "
                             "another Output(history=...) path")
        for attr in engine.written_attributes:
            if attr not in other.written_attributes:
                continue
            if attr == "state.temp":        # YADE's one temperature: only bodies apart (masks) keep both
                m1, m2 = getattr(engine.reader, "mask", None), getattr(other.reader, "mask", None)
                if m1 is not None and m2 is not None and not (int(m1) & int(m2)):
                    continue
                advice = "give the two engines bodies apart (Reader(mask=...)), or make one engine of both"
            else:
                advice = "give one of them another Output(write_back=...)"
            warnings.warn(f"engines {other.label!r} and {engine.label!r} both write b.{attr} on the bodies: the last "
                          f"one to run wins; {advice}", stacklevel=4)


def attach(label: Optional[str] = None, O=None, **overrides):
    """Re-attach the engine saved in the current scene under ``label`` (the only one when
    None) and return it; it continues exactly where the saved run was (values, thermal clock,
    energies, temperatures from ``b.state.temp``, history appended). ``overrides`` replace
    saved constructor arguments (e.g. selectors that could not be saved)."""
    from .runtime import import_yade
    O = O if O is not None else import_yade().Omega()
    labels = persistence.saved_labels(O)
    if label is None:
        if len(labels) != 1:
            raise ValueError(f"give the label of the engine to attach; the scene holds {labels or 'none'}")
        label = labels[0]
    config = persistence.load_config(O, label)
    if config is None:
        raise KeyError(f"the scene holds no saved yade-electro engine labelled {label!r}; it holds {labels or 'none'}")
    old = ENGINES.get(label)
    if old is not None and old.live:
        return old
    if old is not None:
        ENGINES.pop(label, None)
    return engine_class(config["engine"]).resumed(config, label, O, overrides)


def run(label: str):
    """The PyRunner entry point: one step of the engine ``label`` (re-attached if needed)."""
    engine = ENGINES.get(label)
    if engine is None or engine.removed:
        from .runtime import MPY_REFUSAL, in_mpy_subdomain
        if in_mpy_subdomain():             # before a re-attach reads a subdomain's bodies
            raise RuntimeError(MPY_REFUSAL.format(label=label))
        from .runtime import import_yade
        O = import_yade().Omega()
        if persistence.load_config(O, label) is None:
            raise KeyError(f"no yade-electro engine labelled {label!r} in this process or in the scene")
        sys.stderr.write(f"yade-electro: re-attaching engine {label!r} from the loaded scene\n")
        engine = attach(label, O)
    return engine.step()
