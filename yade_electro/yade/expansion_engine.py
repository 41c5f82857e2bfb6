"""``ThermalExpansion``: temperatures that expand the packing, in the YADE loop.

Put it in ``O.engines`` after the engine that writes the temperatures (``HeatEngine``,
``ElectroThermalEngine``, or a script setting ``b.state.temp``)::

    O.engines += [heat.runner, ThermalExpansion(alpha=1.2e-5, mode="bonds").runner]

At each call it reads every sphere's ``b.state.temp`` [K], turns it into a thermal strain
(:func:`~yade_electro.physics.expansion.thermal_strain`, from each element's reference
temperature) and applies the change since the last call:

* ``mode='bonds'``: each cohesive bond's rest length grows (YADE's ``CohFrictPhys.unp``, the
  normal displacement at which the bond carries no force, goes down by the growth), its two
  halves each with its own element's strain; radii and geometry are kept;
* ``mode='radii'``: each radius grows, mass kept, inertia ``2/5 m r^2`` following; contacts,
  overlaps and the other engines' conductances follow (their scene readers see the change).

Thermal stress: :meth:`ThermalExpansion.element_stress` (the Love-Weber stress of every
element), :meth:`ThermalExpansion.bond_forces`, the history (``history=``: mean stress
components, the largest bond tension and compression, per call) and :meth:`write_vtk`.

What it needs is checked when it is built: an expansion coefficient per material that is a
finite number >= 0 (or an :class:`~yade_electro.physics.expansion.AlphaTable`), spheres with a
temperature (or ``reference_temperature=`` and a yade-electro heat engine that will write
them), cohesive bonds in ``'bonds'`` mode. Its configuration and state (the strains already
applied) are kept in the scene's tags: after ``O.save`` / ``O.load`` it goes on from where it
was (a new process re-attaches it at its first call). ``remove()`` leaves the strains applied
so far in the packing.

Units: SI (K, 1/K, m, N, Pa).
"""
from __future__ import annotations

import base64
import logging
from typing import Dict, Optional

import numpy as np

from ..core.errors import MaterialError, ThermalError
from ..core.history import History
from ..physics.expansion import (EXPANSION_MODES, check_alpha, bond_rest_increments,
                                 element_stress, radius_growth, thermal_strain, von_mises)
from . import persistence, registry
from .runtime import import_yade
from .scene import probe_replaced

__all__ = ["ThermalExpansion"]

log = logging.getLogger(__name__)


def _packed(a) -> str:
    """A float or int array as base64 text (its raw bytes; a data format, not pickle)."""
    a = np.ascontiguousarray(a)
    return f"{a.dtype.str}:" + base64.b64encode(a.tobytes()).decode("ascii")


def _unpacked(text: str) -> np.ndarray:
    kind, data = text.split(":", 1)
    if kind not in ("<f8", "<i8"):
        raise ValueError(f"unexpected array type {kind!r} in a saved expansion state")
    return np.frombuffer(base64.b64decode(data.encode("ascii")), dtype=np.dtype(kind)).copy()


def _is_thermal_engine(e) -> bool:
    return getattr(e, "live", False) and "state.temp" in getattr(e, "written_attributes", ())


@registry.engine_type
class ThermalExpansion(registry.RegisteredEngine):
    """Thermal expansion of the spheres of the scene (see the module doc).

    Parameters
    ----------
    alpha : float, AlphaTable or dict
        Linear expansion coefficient [1/K] (>= 0), or ``alpha(T)`` as an ``AlphaTable`` of
        (T [K], alpha [1/K]) points; or one per YADE material, ``{material label or id: alpha}``
        (every material of the expanded spheres must be in it).
    mode : {'bonds', 'radii'}
    reference_temperature : float, optional
        The temperature [K] at which the packing has its built geometry (default: each
        sphere's temperature when the engine is built).
    mask : int, optional
        Only the spheres with ``b.mask & mask`` expand.
    iterPeriod : int
    history : str, optional
        CSV file, one row per call (iter, time, T_mean_K, strain_mean, bonds, s_xx_Pa ... the
        mean Love-Weber stress of the expanded spheres, bond_tension_max_N,
        bond_compression_max_N).
    solid_volume : float, optional
        The solid's volume [m^3], for the element volumes of the stress (default: the
        container of the bonded packing, else the convex hull of the centres grown by the mean
        radius, at build).
    label : str, optional
    O : YADE's Omega, optional (default: the current one)
    """

    DEFAULT_LABEL = "expansion"

    def __init__(self, *, alpha, mode: str = "bonds", reference_temperature: Optional[float] = None,
                 mask: Optional[int] = None, iterPeriod: int = 1, history: Optional[str] = None,
                 solid_volume: Optional[float] = None, label: Optional[str] = None, O=None):
        self._setup(alpha=alpha, mode=mode, reference_temperature=reference_temperature, mask=mask,
                    iterPeriod=iterPeriod, history=history, solid_volume=solid_volume, label=label, O=O)

    # -- building --------------------------------------------------------------------------
    def _setup(self, *, alpha, mode, reference_temperature, mask, iterPeriod, history, solid_volume, label, O,
               _resume=None):
        yade = import_yade()
        self.O = O if O is not None else yade.Omega()
        self.removed = False
        self._kwargs = dict(alpha=alpha, mode=mode, reference_temperature=reference_temperature, mask=mask,
                            iterPeriod=iterPeriod, history=history, solid_volume=solid_volume)
        if mode not in EXPANSION_MODES:
            raise ValueError(f"mode must be one of {', '.join(EXPANSION_MODES)}, got {mode!r}")
        self.mode = mode
        if isinstance(iterPeriod, bool) or not isinstance(iterPeriod, (int, np.integer)) or iterPeriod < 1:
            raise ValueError(f"iterPeriod must be an integer >= 1, got {iterPeriod!r}")
        if mask is not None and (isinstance(mask, bool) or not isinstance(mask, (int, np.integer))):
            raise ValueError(f"mask must be an integer group mask, got {mask!r}")
        self.mask = mask
        self._alpha_spec = self._alphas(alpha)
        if reference_temperature is not None:
            from ..core.materials import real_number
            reference_temperature = real_number("reference_temperature (K)", reference_temperature)
            if reference_temperature <= 0:
                raise MaterialError(f"reference_temperature must be > 0 K, got {reference_temperature}")
        if solid_volume is not None:
            from ..core.materials import positive_property
            solid_volume = float(positive_property("solid_volume", solid_volume, unit=" (m^3)"))
        self.label = label if _resume is not None else registry.claim_label(label, self.DEFAULT_LABEL, self.O)
        self._read_bodies()
        state = persistence.load_state(self.O, self.label) if _resume is not None else None
        if state:
            self._t_ref, self._eps = self._aligned(_unpacked(state["ids"]), _unpacked(state["t_ref"]),
                                                   _unpacked(state["eps"]))
            self._phi = float(state["phi"])
            self.calls = int(state.get("calls", 0))
        else:
            T = self._temperatures(at_build=reference_temperature is None)
            if T is None:               # a heat engine of ours writes them at its first call
                if not any(_is_thermal_engine(e) for e in registry.live_engines().values()):
                    raise ThermalError(self._no_temperature_message())
                T = np.full(self._ids.size, np.nan)
            self._t_ref = np.full(self._ids.size, reference_temperature) if reference_temperature is not None else T
            self._eps = np.zeros(self._ids.size)
            self._phi = self._solid_fraction(solid_volume)
            self.calls = 0
        if mode == "bonds" and not self._bonds(need_any=True)[0].size:
            raise MaterialError("mode='bonds' needs cohesive bonds (CohFrictPhys) between the expanded spheres, and "
                                "there is none: run the bonding step first, or use mode='radii' (a loose bed)")
        self._history = History(history, "a" if _resume is not None else "w")
        if state:                               # rows written after the save are not this run's
            self._history.truncate(int(state.get("rows", len(self._history))))
        self.runner = self._find_or_make_runner(iterPeriod)
        registry.ENGINES[self.label] = self
        persistence.save_config(self.O, self.label, {"engine": type(self).__name__, "version": 1,
                                                     "kwargs": dict(self._kwargs), "missing": []})
        self._save_state()

    def _alphas(self, alpha) -> dict:
        """{None: alpha} or {material id: alpha}, every value checked."""
        if not isinstance(alpha, dict):
            return {None: check_alpha("alpha", alpha)}
        mats = {m.label: m.id for m in self.O.materials}
        out = {}
        for k, v in alpha.items():
            if isinstance(k, str):
                if k not in mats:
                    raise MaterialError(f"alpha: no YADE material labelled {k!r} (labels: {sorted(l for l in mats if l)})")
                k = mats[k]
            elif isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= int(k) < len(self.O.materials):
                raise MaterialError(f"alpha: keys are YADE material labels or ids, got {k!r}")
            out[int(k)] = check_alpha(f"alpha[{k!r}]", v)
        if not out:
            raise MaterialError("alpha: the dict of materials is empty")
        return out

    def _aligned(self, ids, t_ref, eps):
        """Reference temperatures and applied strains of the current spheres from those of
        ``ids`` (a sphere not among them: NaN reference, set from its temperature at the next
        call, and no strain applied yet)."""
        order = np.argsort(ids)
        pos = np.clip(np.searchsorted(ids, self._ids, sorter=order), 0, max(ids.size - 1, 0))
        known = ids[order[pos]] == self._ids if ids.size else np.zeros(self._ids.size, bool)
        t = np.where(known, t_ref[order[pos]] if ids.size else np.nan, np.nan)
        e = np.where(known, eps[order[pos]] if ids.size else 0.0, 0.0)
        return t, e

    def _read_bodies(self):
        """The expanded spheres: ids, bodies, radii, material ids (again when bodies change)."""
        yade = import_yade()
        if self.O.periodic:
            raise MaterialError("ThermalExpansion does not take periodic cells yet")
        bodies = [b for b in self.O.bodies if b is not None and isinstance(b.shape, yade.Sphere)
                  and not b.isClumpMember and (self.mask is None or b.mask & self.mask)]
        if not bodies:
            raise MaterialError("ThermalExpansion: no sphere to expand (check mask=)")
        self._bodies = bodies
        self._ids = np.array([b.id for b in bodies], dtype=np.int64)
        self._index = {int(i): k for k, i in enumerate(self._ids)}
        self._n_bodies = len(self.O.bodies)
        self._probe = (int(self._ids[0]), bodies[0])
        mat = np.array([b.material.id for b in bodies], dtype=np.int64)
        if None not in self._alpha_spec:
            missing = sorted(set(mat.tolist()) - set(self._alpha_spec))
            if missing:
                names = [self.O.materials[m].label or str(m) for m in missing]
                raise MaterialError(f"alpha has no value for the material(s) {names} of expanded spheres; give one "
                                    "for each, or mask= them out")
        self._material = mat

    def _temperatures(self, at_build=None) -> Optional[np.ndarray]:
        """b.state.temp of the expanded spheres [K]; None at build when some have none (or
        not > 0); a ThermalError at a call."""
        T = np.array([getattr(b.state, "temp", np.nan) for b in self._bodies], dtype=float)
        bad = ~(np.isfinite(T) & (T > 0))
        if np.any(bad):
            if at_build is not None:
                if at_build:
                    raise ThermalError(self._no_temperature_message(self._ids[bad]))
                return None
            raise ThermalError(f"expansion {self.label!r}: spheres {self._ids[bad][:10].tolist()} have no temperature "
                               f"> 0 K (b.state.temp = {T[bad][:5].tolist()}); the engine writing temperatures must "
                               "run before this one in O.engines")
        return T

    def _no_temperature_message(self, ids=None) -> str:
        which = f"spheres {ids[:10].tolist()} have" if ids is not None else "the spheres have"
        return (f"ThermalExpansion: {which} no temperature (b.state.temp > 0 K, YADE's ThermalState): set them "
                "(yade_electro.yade.ensure_thermal_state(bodies), then b.state.temp = ...), run the heat engine once "
                "(engine.step()) before building this one, or give reference_temperature= with a yade-electro heat "
                "engine in the scene")

    def _solid_fraction(self, solid_volume) -> float:
        r = np.array([b.shape.radius for b in self._bodies])
        spheres = float(np.sum(4.0 / 3.0 * np.pi * r ** 3))
        container = persistence.scene_container(self.O) if solid_volume is None else None
        if container is not None:               # the packing's own container (add_bonded_packing)
            from ..geometry.volumes import container_volume
            solid_volume = float(container_volume(container)[0])
        if solid_volume is None:
            from scipy.spatial import ConvexHull
            pos = np.array([tuple(b.state.pos) for b in self._bodies])
            try:
                hull = ConvexHull(pos)
                solid_volume = hull.volume + hull.area * float(r.mean())
            except Exception:                   # flat or tiny sets: the spheres themselves
                solid_volume = spheres
        return min(1.0, spheres / solid_volume)

    # -- the scene ----------------------------------------------------------------------------
    def _bonds(self, need_any=False):
        """(pairs (m, 2) of element indices, phys list) of the real interactions with ``unp``
        between expanded spheres (CohFrictPhys: bonds, and contacts in 'bonds' mode)."""
        pairs, phys = [], []
        index = self._index
        for inter in self.O.interactions:
            if not inter.isReal:
                continue
            a, b = index.get(inter.id1), index.get(inter.id2)
            if a is None or b is None:
                continue
            ph = inter.phys
            if not hasattr(ph, "unp"):
                continue
            if need_any and getattr(ph, "cohesionBroken", True):
                continue
            pairs.append((a, b))
            phys.append(ph)
            if need_any:
                break
        return np.asarray(pairs, dtype=np.int64).reshape(-1, 2), phys

    def _strain_of(self, T) -> np.ndarray:
        t_ref = self._t_ref
        eps = np.empty(T.size)
        for mid, alpha in self._alpha_spec.items():
            on = np.ones(T.size, bool) if mid is None else self._material == mid
            eps[on] = thermal_strain(T[on], t_ref[on], alpha)
        return eps

    # -- one call -----------------------------------------------------------------------------
    @property
    def live(self) -> bool:
        """Registered, not removed, and its scene is the current one."""
        return not self.removed and not probe_replaced(self.O, self._probe)

    @property
    def history(self) -> History:
        return self._history

    @property
    def written_attributes(self) -> tuple:
        return ("shape.radius",) if self.mode == "radii" else ()

    def step(self):
        """Apply the strain change since the last call (what the PyRunner calls); returns the
        history row."""
        if self.removed:
            raise RuntimeError(f"engine {self.label!r} was removed")
        if probe_replaced(self.O, self._probe):     # O.load in this process: go on from its state
            config = persistence.load_config(self.O, self.label)
            if config is None:
                raise RuntimeError(f"engine {self.label!r}: its scene was replaced and the new one holds no saved "
                                   "engine of that label; build a new engine")
            registry.ENGINES.pop(self.label, None)
            self._setup(**dict(config["kwargs"]), label=self.label, O=self.O, _resume=config)
        if len(self.O.bodies) != self._n_bodies:        # bodies added or erased
            old = self._ids, self._t_ref, self._eps
            self._read_bodies()
            self._t_ref, self._eps = self._aligned(*old)
        T = self._temperatures()
        new = ~np.isfinite(self._t_ref)                # spheres seen for the first time start here
        self._t_ref[new] = T[new]
        eps = self._strain_of(T)
        before = self._eps
        if self.mode == "bonds":
            pairs, phys = self._bonds()
            if phys:
                r = np.array([b.shape.radius for b in self._bodies])
                unp = np.array([p.unp for p in phys])
                rest = r[pairs[:, 0]] + r[pairs[:, 1]] - unp
                for p, v in zip(phys, (unp - bond_rest_increments(pairs, r, rest, eps, before)).tolist()):
                    p.unp = v
            n_bonds = len(phys)
        else:
            r = np.array([b.shape.radius for b in self._bodies])
            new = radius_growth(r, eps, before)
            for b, rn, ro in zip(self._bodies, new.tolist(), r.tolist()):
                if rn != ro:
                    b.shape.radius = rn
                    b.state.inertia = b.state.inertia * (rn / ro) ** 2
            n_bonds = 0
        self._eps = eps
        self.calls += 1
        row = {"iter": int(self.O.iter), "time": float(self.O.time), "T_mean_K": float(T.mean()),
               "strain_mean": float(eps.mean()), "interactions": int(n_bonds)}
        if self._history.path:
            read = self.read_interactions()
            s = self.element_stress(read)
            V = self.element_volumes()
            mean = np.einsum("n,nij->ij", V, s) / V.sum()
            fn, _ = self.bond_forces(read)
            row.update({f"s_{a}_Pa": float(mean[i, j]) for a, (i, j) in
                        zip(("xx", "yy", "zz", "xy", "yz", "zx"), ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)))})
            row["bond_tension_max_N"] = float(max(fn.max(initial=0.0), 0.0))
            row["bond_compression_max_N"] = float(max(-fn.min(initial=0.0), 0.0))
        self._history.append(row)
        self._save_state()
        return row

    def _save_state(self):
        ids = self._ids
        persistence.save_state(self.O, self.label, {
            "ids": _packed(ids), "t_ref": _packed(self._t_ref), "eps": _packed(self._eps), "phi": self._phi,
            "calls": self.calls, "rows": len(self._history)})

    # -- read-out -----------------------------------------------------------------------------
    def read_interactions(self):
        """(positions, pairs, contact points, force on the second body [N]) of every real
        interaction between expanded spheres: one read of the scene, which the stress and
        the bond forces share."""
        pairs, pts, force = [], [], []
        index = self._index
        for inter in self.O.interactions:
            if not inter.isReal:
                continue
            a, b = index.get(inter.id1), index.get(inter.id2)
            if a is None or b is None:
                continue
            ph = inter.phys
            f = ph.normalForce + getattr(ph, "shearForce", ph.normalForce * 0)
            pairs.append((a, b))
            pts.append(tuple(inter.geom.contactPoint))
            force.append(tuple(f))
        return (self._positions(), np.asarray(pairs, np.int64).reshape(-1, 2), np.asarray(pts, float).reshape(-1, 3),
                np.asarray(force, float).reshape(-1, 3))

    def _positions(self):
        return np.array([tuple(b.state.pos) for b in self._bodies])

    def element_volumes(self) -> np.ndarray:
        """Each element's volume [m^3]: its sphere's over the solid fraction at build (cells
        grow with the element in 'radii' mode, as the spheres)."""
        r = np.array([b.shape.radius for b in self._bodies])
        if self.mode == "bonds":
            r = r * (1.0 + self._eps)
        return 4.0 / 3.0 * np.pi * r ** 3 / self._phi

    def element_stress(self, read=None) -> np.ndarray:
        """The Love-Weber stress (n, 3, 3) [Pa] of every expanded sphere now, tension positive
        (rows as :attr:`ids`). ``read``: what :meth:`read_interactions` returned, to share one read."""
        pos, pairs, pts, f = self.read_interactions() if read is None else read
        return element_stress(pos, pairs, pts, f, self.element_volumes())

    def bond_forces(self, read=None) -> "tuple[np.ndarray, np.ndarray]":
        """(normal force [N], tension positive; shear force magnitude [N]) of every real
        interaction between expanded spheres, and their (m, 2) body ids: returns
        ``(normal, shear)`` with ``self.last_bond_ids`` set. ``read`` as for
        :meth:`element_stress`."""
        pos, pairs, pts, f = self.read_interactions() if read is None else read
        d = pos[pairs[:, 1]] - pos[pairs[:, 0]]
        n = d / np.linalg.norm(d, axis=1)[:, None]
        fn = np.einsum("mi,mi->m", f, n)
        self.last_bond_ids = self._ids[pairs]
        return -fn, np.linalg.norm(f - fn[:, None] * n, axis=1)

    @property
    def ids(self) -> np.ndarray:
        """Body ids of the expanded spheres, in the order of the read-outs."""
        return self._ids.copy()

    def write_vtk(self, prefix: str) -> Dict[str, str]:
        """``<prefix>_particles.vtu`` (radius, temperature, thermal strain, stress components
        s_xx ... [Pa], von Mises and mean stress) and ``<prefix>_bonds.vtu`` (normal force,
        tension positive, and shear force [N] per interaction). Returns the two paths."""
        from ..post.vtk import write_bonds, write_elements
        read = self.read_interactions()
        s = self.element_stress(read)
        pos = read[0]
        r = np.array([b.shape.radius for b in self._bodies])
        fields = {"temperature": self._temperatures(), "thermal_strain": self._eps.copy(),
                  "body_id": self._ids.astype(float), "von_mises_Pa": von_mises(s),
                  "mean_stress_Pa": np.trace(s, axis1=1, axis2=2) / 3.0}
        for a, (i, j) in zip(("xx", "yy", "zz", "xy", "yz", "zx"), ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0))):
            fields[f"s_{a}_Pa"] = s[:, i, j]
        fn, fs = self.bond_forces(read)
        pairs = np.searchsorted(self._ids, self.last_bond_ids) if np.all(np.diff(self._ids) > 0) else \
            np.vectorize(self._index.get)(self.last_bond_ids)
        return {"particles": write_elements(f"{prefix}_particles.vtu", pos, r, fields),
                "bonds": write_bonds(f"{prefix}_bonds.vtu", pos, pairs.reshape(-1, 2),
                                     {"normal_force_N": fn, "shear_force_N": fs})}
