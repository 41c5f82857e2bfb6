"""What every engine shares: the PyRunner lifecycle, selectors, materials by YADE material,
the history, save and load (configuration and state in ``O.tags``), and the checks made when an
engine is built."""

from __future__ import annotations

import functools
import inspect
import logging
import os
import warnings
from typing import Dict, Optional

import numpy as np

from ..core import codec
from ..core.errors import BoundaryConditionError, MaterialError
from ..geometry.shapes import Shape
from ..core.history import History
from ..core.materials import real_number
from . import persistence
from . import registry
from .runtime import MPY_REFUSAL, import_yade, in_mpy_subdomain
from .distributed import PETSC_SOLVERS, distributed_requested, slab_region, world_rank
from .granular import GranularReader
from .scene import SceneReader, predicate_selector
from .writeback import check_write_back

__all__ = ["EngineBase", "synced_property", "electrode_walls", "material_table", "is_predicate", "check_period",
           "REMOVED_KEYWORDS", "keyword_only"]

log = logging.getLogger(__name__)


#: Keywords of the engines before their option objects, and where each went.
REMOVED_KEYWORDS = {
    "resistivity": "material=Material(resistivity=...)",
    "density": "material=Material(density=...)",
    "specific_heat": "material=Material(specific_heat=...)",
    "conductivity": "material=Material(conductivity=...)",
    "beta": "material=Material(beta=..., reference_temperature=...)",
    "materials": "material=Materials(default=Material(...), by_yade_material={label: Material(...)})",
    "electrodes": "boundaries=[Electrode('top', surface=... | select=... | wall=..., potential=... | current=...), ...]",
    "fixed": "boundaries=[FixedTemperature(...), ...]",
    "flux": "boundaries=[HeatFlux(...), ...]",
    "convection": "boundaries=[Convection(...), ...]",
    "sources": "boundaries=[HeatSource(...), ...]",
    "walls": "boundaries=[Wall('shell', bodies=ids, temperature=K or None), ...]",
    "initial_temperature": "temperature=InitialTemperature(K, by_id={id: K})",
    "theta": "integrator=Integrator(theta=...)",
    "thermal_dt": "integrator=Integrator(dt=...)",
    "time_scale": "integrator=Integrator(time_scale=...)",
    "steady": "integrator=Integrator(steady=True)",
    "thermal_solver": "integrator=Integrator(solver=...)",
    "eta": "integrator=Integrator(eta=...)",
    "coupled_options": "integrator=Integrator(coupling_iterations=..., subcycle=..., safety=...) or "
                       "law=Law(..., volume_fraction=...)",
    "law_params": "law=Law(name, **params)",
    "container": "law=Law(name, container=...)",
    "measure": "output=Output(measure=(a, b))",
    "history": "output=Output(history='file.csv')",
    "history_mode": "output=Output(history_mode=...)",
    "write_back": "output=Output(write_back=...)",
    "plot": "output=Output(plot=True)",
    "bonds": "reader=Reader(bonds=...)",
    "mask": "reader=Reader(mask=...)",
    "geometry_every": "reader=Reader(geometry_every=...)",
    "move_tolerance": "reader=Reader(move_tolerance=...)",
    "full_read_every": "reader=Reader(full_read_every=...)",
    "bond_check": "reader=Reader(bond_check=...)",
    "sweep_calls": "reader=Reader(sweep_calls=...)",
    "skin": "reader=Reader(skin=...)",
    "isolated": "reader=Reader(isolated=...)",
    "reselect": "reader=Reader(reselect=True)",
    "overlap": "reader=Reader(overlap=True)",
}


def keyword_only(init):
    """Decorator of an engine's ``__init__``: a positional argument, or a keyword that moved into
    an option object, raises TypeError in the user's script saying where it went."""
    params = inspect.signature(init).parameters
    known = [p for p in params if p != "self"]

    @functools.wraps(init)
    def wrapper(self, *args, **kwargs):
        name = type(self).__name__
        if args:
            raise TypeError(f"{name} takes keyword arguments only ({', '.join(known)}); e.g. "
                            f"{name}(material=Material(...), ...). Physics values are never positional.")
        moved = [k for k in kwargs if k not in params and k in REMOVED_KEYWORDS]
        if moved:
            raise TypeError(f"{name}: {', '.join(repr(k) for k in moved)} moved into the engine's option objects: "
                            + "; ".join(f"{k} -> {REMOVED_KEYWORDS[k]}" for k in moved)
                            + " (from yade_electro.yade import Material, Electrode, Law, Integrator, Reader, Output)")
        unknown = [k for k in kwargs if k not in params]
        if unknown:
            raise TypeError(f"{name}: unknown keyword(s) {unknown}; it takes {', '.join(known)}")
        return init(self, **kwargs)
    return wrapper


def is_predicate(obj) -> bool:
    return callable(obj) and hasattr(obj, "aabb") and hasattr(obj, "dim") and not isinstance(obj, Shape)


def electrode_walls(electrodes) -> dict:
    """name -> body ids of the electrodes on walls (``Electrode(wall=ids)``, granular mode)."""
    return {e.name: list(e.wall) for e in electrodes or () if getattr(e, "wall", None) is not None}


def material_table(O, materials, allowed) -> Dict[int, Dict[str, float]]:
    """``materials={YADE material label or index: dict(property=value)}`` checked against
    ``O.materials`` and the ``allowed`` property names, as {material index: {name: value}}
    (values finite and > 0, SI units). MaterialError saying what to fix."""
    if materials is None:
        return {}
    if not isinstance(materials, dict):
        raise MaterialError("materials= must be a dict YADE material (label or index in O.materials) -> "
                            f"dict({', '.join(f'{a}=...' for a in allowed)}), got {type(materials).__name__}")
    labels = {}
    for k, m in enumerate(O.materials):
        labels.setdefault(m.label, []).append(k)
    out = {}
    for key, values in materials.items():
        if isinstance(key, str):
            found = labels.get(key, [])
            if len(found) != 1:
                known = sorted(lab for lab in labels if lab)
                raise MaterialError(f"materials: {'no' if not found else 'more than one'} material labelled {key!r} in "
                                    f"O.materials (labels: {known}); give a unique label or the material's index")
            mid = found[0]
        elif isinstance(key, (int, np.integer)) and not isinstance(key, bool):
            if not 0 <= int(key) < len(O.materials):
                raise MaterialError(f"materials: no material {key} in O.materials (it has {len(O.materials)})")
            mid = int(key)
        else:
            raise MaterialError(f"materials: a key must be a material's label or index in O.materials, got {key!r}")
        if not isinstance(values, dict) or not values:
            raise MaterialError(f"materials[{key!r}]: give dict({', '.join(f'{a}=...' for a in allowed)})")
        unknown = sorted(set(values) - set(allowed))
        if unknown:
            raise MaterialError(f"materials[{key!r}]: unknown propert{'y' if len(unknown) == 1 else 'ies'} "
                                f"{unknown}; this engine takes {list(allowed)}")
        checked = {}
        for name, v in values.items():
            x = real_number(f"materials[{key!r}][{name!r}]", v)
            if not x > 0:
                raise MaterialError(f"materials[{key!r}][{name!r}] must be > 0, got {v!r}")
            checked[name] = x
        if mid in out:
            raise MaterialError(f"materials: material {key!r} is given twice (by label and by index)")
        out[mid] = checked
    return out


def check_period(iterPeriod):
    if isinstance(iterPeriod, bool) or not isinstance(iterPeriod, (int, np.integer)) or iterPeriod <= 0:
        raise ValueError(f"iterPeriod must be an integer >= 1 (steps between two calls), got {iterPeriod!r}")
    return int(iterPeriod)


def synced_property(name: str, doc: str) -> property:
    """A read-only attribute ``name`` read after ``self.sync()`` (``overlap=True``: the last
    call is computed and published first; on the worker thread, as it is)."""
    def get(self):
        self.sync()
        return getattr(self, name)
    return property(get, doc=doc + " With overlap=True, reading it waits for the last call and publishes it.")


class EngineBase(registry.RegisteredEngine):
    """What both engines share: configuration, scene reader, runner, history, state tags."""

    DEFAULT_LABEL = "electro"
    #: heat conduction only (no electrodes): periodic cells are taken in the granular mode
    _heat_only = False
    #: per-material properties {YADE material index: {name: value}} (see ``materials=``)
    _materials: Dict[int, Dict[str, float]] = {}
    _materials_config = None
    _materials_at = None

    def _start(self, O, label, resume, iterPeriod, reader_options, history, history_mode, write_back, plot):
        yade = import_yade()
        self.O = O if O is not None else yade.Omega()
        self.removed = False
        self.error = None
        self._resume = resume
        self.label = label if resume is not None else registry.claim_label(label, self.DEFAULT_LABEL, self.O)
        self.iterPeriod = check_period(iterPeriod)
        opts = dict(reader_options)
        skin, walls, clumps = opts.pop("skin", "auto"), opts.pop("walls", None), opts.pop("clumps", None)
        isolated = opts.pop("isolated", "keep")
        if opts["bonds"] == "contacts":
            self._reader = GranularReader(self.O, mask=opts["mask"], skin=skin, walls=walls,
                                          periodic=self._heat_only, clumps=clumps is not None)
        else:
            if self._declared_walls:
                raise BoundaryConditionError("walls (Wall, or Electrode(wall=...)) conduct in the granular mode "
                                             "only (Reader(bonds='contacts')): a bonded solid's boundaries are surfaces "
                                             "(surface=)")
            self._reader = SceneReader(self.O, **opts, clumps=clumps is not None, isolated=isolated)
        if history_mode not in ("w", "a", "x"):
            raise ValueError(f"history_mode must be 'w', 'a' or 'x', got {history_mode!r}")
        self.history_path = None if history is None else os.fspath(history)
        self.write_back = write_back
        if not isinstance(plot, bool):
            raise ValueError(f"plot must be True or False, got {plot!r}")
        self.plot = plot
        self._written = None

    def _normalise_selector(self, sel):
        if is_predicate(sel):
            return predicate_selector(sel)
        if isinstance(sel, dict) and set(sel) == {"mask"}:
            m = sel["mask"]
            if isinstance(m, bool) or not isinstance(m, (int, np.integer)):
                raise BoundaryConditionError(f"dict(mask=...) needs an integer group mask, got {m!r}")
            reader = self.reader

            def by_mask(pos, radius):
                return np.array([bool(b.mask & int(m)) for b in reader.bodies])
            return by_mask
        return sel

    def _apply_materials(self):
        """Give the models per-element properties from the YADE materials of the elements read
        (again only after a full read: the element set changes only there)."""
        if not self._materials or self._materials_at == self.reader.full_reads:
            return
        mat_ids = np.array([b.material.id for b in self.reader.bodies], dtype=np.int64)
        base = self._material_base()
        props = {}
        for name in sorted({k for v in self._materials.values() for k in v}):
            arr = np.full(mat_ids.size, np.nan)
            if base.get(name) is not None:
                arr[:] = float(base[name])
            for mid, values in self._materials.items():
                if name in values:
                    arr[mat_ids == mid] = values[name]
            if np.isnan(arr).any():
                raise MaterialError(f"{name} is given for some materials only and not to the engine: elements of "
                                    f"the other materials have none; give {name}= to the engine too")
            props[name] = arr
        self._set_properties(props)
        self._materials_at = self.reader.full_reads

    def _finish(self, history_mode):
        """After the model is built: first read, checks, history, runner, saved config."""
        distributed = distributed_requested(self._distributed_solver())
        self._slabs = slab_region(self._options["law"], self._law_params,
                                  cells=bool(self._surface_names())) if distributed else None
        if self._slabs is not None:                 # plain mpiexec: no rank reads the whole scene
            self.reader.region = self._slabs.region
            self.reader.invalidate()
        graph = self.reader.read()                  # no spheres: GraphError here, in the script
        check_write_back(self.write_back, self.reader.bodies)
        self._distributed = None
        if distributed:
            if self._resume is not None:
                raise RuntimeError(f"engine {self.label!r}: a distributed run does not continue a saved one yet")
            self._distributed = self._distributed_calls(graph)     # its errors here, in the script
            if world_rank() != 0:
                self.history_path = None            # rank 0 writes the history
        else:
            self._check_bonded(graph)
            self._prepare(graph)                    # selections, structure: their errors here too
        mode = "a" if self._resume is not None else history_mode
        self._history = History(self.history_path, mode)
        registry.check_shared_outputs(self)
        if self._resume is not None:
            self._restore_history(self._resume_state)
        self.runner = self._find_or_make_runner(self.iterPeriod)
        registry.ENGINES[self.label] = self
        self._save_config()
        self._save_state()

    def _check_bonded(self, graph):
        """A bonded solid with no bond at all: refused when something has run (the bonding step was
        forgotten, the packing is cohesionless); before the first step, said (bonds made by YADE's
        first steps, ``setCohesionNow``, are read then)."""
        if self._options.get("bonds") != "cohesive" or graph.n_nodes < 2 or len(graph.edges) or self._resume is not None:
            return
        said = (f"engine {self.label!r}: none of the {graph.n_nodes} spheres is bonded to another (a bonded solid, "
                "Reader(bonds='cohesive'), conducts through its cohesive bonds): run the bonding step first "
                "(yade_electro.yade.packing.add_bonded_packing, or CohFrictMat with setCohesionNow and one O.step()), "
                "or use Reader(bonds='contacts') for a cohesionless packing")
        if int(self.O.iter) > 0 or self.O.interactions.countReal() > 0:
            raise BoundaryConditionError(said)
        warnings.warn(said + "; nothing has run yet, so the bonds may still come from the first steps",
                      stacklevel=4)

    @property
    def reader(self):
        """The engine's scene reader (SceneReader, or GranularReader with ``bonds='contacts'``)."""
        return self._reader

    @property
    def history(self) -> History:
        """The engine's History (one row per call)."""
        return self._history

    # -- persistence ---------------------------------------------------------------------------
    def _save_config(self):
        kwargs = self._config_kwargs()
        saved, missing = {}, []
        for k, v in kwargs.items():
            try:
                codec.dumps(v)
                saved[k] = v
            except TypeError:
                missing.append(k)
        if missing:
            log.warning("engine %r: %s cannot be saved with the scene; after O.load, attach(%r, %s=...) must give "
                        "them again", self.label, ", ".join(missing), self.label, missing[0])
        persistence.save_config(self.O, self.label, {"engine": type(self).__name__, "version": 1,
                                                     "kwargs": saved, "missing": missing})

    def _restore_history(self, state):
        rows = int(state.get("rows", len(self.history))) if state else len(self.history)
        extra = self.history.truncate(rows)
        replayed = state.get("overlap_iter") if state else None
        if extra and replayed is not None and int(float(extra[0].get("iter", -1))) == int(replayed):
            extra = extra[1:]       # the unpublished overlapped call's row: the replay writes it again
        if extra and self.history.path:
            side = self.history.path + ".after-save.csv"
            h = History(side, "w")
            for r in extra:
                h.append(r)
            warnings.warn(f"history {self.history.path!r} had {len(extra)} row(s) written after the scene was saved; "
                          f"they are moved to {side!r} and the run continues from the save", stacklevel=4)

    @property
    def _resume_state(self):
        return persistence.load_state(self.O, self.label) or {}

    # -- liveness, removal ---------------------------------------------------------------------
    @property
    def live(self) -> bool:
        """Registered, not removed, and its scene is the current one."""
        return not self.removed and not self.reader.scene_replaced

    @property
    def written_attributes(self) -> tuple:
        return (self.write_back,) if self.write_back else ()

    def _reattach_in_place(self):
        """The scene was replaced (``O.load`` in this process): continue from what it saved."""
        config = persistence.load_config(self.O, self.label)
        if config is None:
            raise RuntimeError(f"engine {self.label!r}: the scene it ran on was replaced (O.load of another scene, or "
                               "O.reset) and the new one holds no saved engine of that label; build a new engine")
        log.warning("engine %r: the scene was replaced (O.load): continuing from the state it saved", self.label)
        kwargs = dict(config["kwargs"])
        registry.ENGINES.pop(self.label, None)
        self._setup(**kwargs, label=self.label, O=self.O, _resume=config)

    # -- one call ------------------------------------------------------------------------------
    def step(self):
        """One call on the current scene (what the PyRunner calls); returns its history row
        (None for an overlapped call: ``sync()`` returns it once computed)."""
        return self._guarded(self._step)

    def _guarded(self, fn):
        try:
            if self.removed:
                raise RuntimeError(f"engine {self.label!r} was removed")
            if self._distributed is not None:
                out = self._distributed.call()
                self._write_row(out)
                return out
            if in_mpy_subdomain():
                raise RuntimeError(MPY_REFUSAL.format(label=self.label))
            if self._reader.scene_replaced:
                self._reattach_in_place()
            out = fn()
        except Exception as exc:
            self.error = exc
            log.error("yade-electro engine %r failed at iteration %d: %s: %s", self.label, int(self.O.iter),
                      type(exc).__name__, exc)
            if self._distributed is not None:       # the other ranks wait in a collective call: end them all
                self._distributed.abort(exc)
            raise
        self._save_state()
        return out

    _distributed = None

    def _distributed_solver(self) -> Optional[str]:
        """The PETSc solver name that makes this engine distributed under mpiexec (its
        ``solver``, or for a heat engine the integrator's), or None."""
        for name in (self._options.get("solver"), getattr(self, "_thermal", {}).get("thermal_solver")):
            if isinstance(name, str) and name in PETSC_SOLVERS:
                return name
        return None

    def _surface_names(self) -> dict:
        """name -> surface of the engine's electrodes and conditions given on a surface (a
        subclass's)."""
        return {}

    def _distributed_calls(self, graph):
        """The DistributedCalls of this engine on the first ``graph`` (a subclass's)."""
        raise BoundaryConditionError(f"{type(self).__name__} does not run distributed; use solver='cg-deflated'")

    @property
    def distributed(self) -> bool:
        """True when the engine runs distributed over the ranks of mpiexec (solver='petsc')."""
        return self._distributed is not None

    def _write_row(self, row):
        if getattr(self._reader, "bonds", None) == "cohesive":    # how soon a bond broken now is seen
            row["bond_check_calls"] = int(self._reader.bond_check_calls)
        self.history.append(row)
        if self.plot:
            self._plot_row(row)

    @staticmethod
    def _plot_row(row):
        from yade import plot
        plot.addData(**{f"electro_{k}" if k not in ("iter", "time") else k: v for k, v in row.items()})


#: why an engine does not run inside yade.mpy's domain decomposition
