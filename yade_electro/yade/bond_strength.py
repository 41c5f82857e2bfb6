"""Moment strength of CohFrictMat bonds, which YADE 2023.02a lacks.

In YADE 2023.02a a fragile ``CohFrictPhys`` bond breaks only on its normal force (tension
above ``normalAdhesion``) or its shear force (above ``shearAdhesion + F_n tan phi``); its
bending and twisting moments grow without limit. A bonded packing twisted or bent then keeps
ligaments that hold by their moments alone (in the pin torsion case, 429 bonds at 18 times a
beam's bending strength after the crack). Later YADE versions give each bond the moment
strengths of a circular beam of radius r = min(r1, r2) with YADE's section r^2:

* rolling (bending): ``rollingAdhesion = normalAdhesion r / 4`` (pure bending stress 4 M / (A r));
* twisting: ``twistingAdhesion = shearAdhesion r / 2`` (pure twisting stress 2 M / (A r)).

:class:`MomentStrength` applies these limits from a PyRunner: every ``iterPeriod`` steps it
reads each intact bond's moments and breaks the bonds above their limit as YADE's own
``SetBreakingState`` does (``cohesionBroken = True``, adhesions 0: the bond becomes a
frictional contact, erased by YADE if its spheres part). Cost: about 2 us per bond per check
(Python reads of two moments); a bond can exceed its limit for up to ``iterPeriod`` steps.

Units: SI (N m, Pa, m).
"""
from __future__ import annotations

import operator
from typing import Iterable, Optional

import numpy as np

from .runtime import import_yade

__all__ = ["MomentStrength"]

_STATE = operator.attrgetter("cohesionBroken", "moment_bending", "moment_twist")


class MomentStrength:
    """Bending and twisting strength of the scene's intact CohFrictMat bonds.

    Parameters
    ----------
    iterPeriod : int
        Steps between two checks.
    exclude : iterable of int, optional
        Body ids whose bonds are never broken (e.g. grips).
    label : str
        Label of the PyRunner.

    ``strength.runner`` goes in ``O.engines`` (after NewtonIntegrator); ``strength.broken``
    counts the bonds it broke.
    """

    def __init__(self, iterPeriod: int = 100, exclude: Optional[Iterable[int]] = None, label: str = "moment_strength",
                 O=None):
        yade = import_yade()
        from yade import wrapper as W
        self.O = O if O is not None else yade.Omega()
        if isinstance(iterPeriod, bool) or int(iterPeriod) != iterPeriod or iterPeriod < 1:
            raise ValueError(f"iterPeriod must be an integer >= 1, got {iterPeriod!r}")
        if not (isinstance(label, str) and label.isidentifier()) or label in _LIVE:
            raise ValueError(f"label must be a new Python identifier, got {label!r} (taken: {sorted(_LIVE)})")
        skip = set(int(i) for i in (exclude or ()))
        phys, r = [], []
        for i in self.O.interactions:
            if not i.isReal or not hasattr(i.phys, "moment_bending") or i.phys.cohesionBroken:
                continue
            if i.id1 in skip or i.id2 in skip:
                continue
            phys.append(i.phys)
            r.append(min(self.O.bodies[i.id1].shape.radius, self.O.bodies[i.id2].shape.radius))
        self._phys = phys
        r = np.asarray(r, float)
        self.max_bending = np.array([p.normalAdhesion for p in phys]) * r / 4.0
        self.max_twist = np.array([p.shearAdhesion for p in phys]) * r / 2.0
        self.broken = 0
        self.checks = 0
        self.label = label
        self.runner = W.PyRunner(iterPeriod=int(iterPeriod), label=label,
                                 command=f"import yade_electro.yade.bond_strength as _b; _b._LIVE[{label!r}].check()")
        _LIVE[label] = self

    def _read(self):
        """(alive, bending, twisting) of each watched bond, in one pass over them."""
        m = [_STATE(p) for p in self._phys]
        alive = np.fromiter((not a for a, _, _ in m), bool, count=len(m))
        mb = np.fromiter((b.norm() for _, b, _ in m), float, count=len(m))
        mt = np.fromiter((t.norm() for _, _, t in m), float, count=len(m))
        return alive, mb, mt

    def loads(self):
        """(bending, twisting) moment of each watched bond over its limit (> 1: it breaks;
        bonds broken since the last check included)."""
        _, mb, mt = self._read()
        with np.errstate(divide="ignore", invalid="ignore"):
            return mb / self.max_bending, mt / self.max_twist

    def check(self) -> int:
        """Break the intact bonds whose bending or twisting moment exceeds its limit; returns
        how many broke now."""
        self.checks += 1
        if not self._phys:
            return 0
        alive, mb, mt = self._read()
        with np.errstate(divide="ignore", invalid="ignore"):
            over = np.flatnonzero(alive & ((mb > self.max_bending) | (mt > self.max_twist)))
        for k in over.tolist():
            p = self._phys[k]
            p.cohesionBroken = True
            p.normalAdhesion = 0.0
            p.shearAdhesion = 0.0
        self.broken += int(over.size)
        alive[over] = False
        if not alive.all():                         # broken (by YADE, the script or here): stop watching
            keep = np.flatnonzero(alive)
            self._phys = [self._phys[k] for k in keep]
            self.max_bending, self.max_twist = self.max_bending[keep], self.max_twist[keep]
        return int(over.size)

    def remove(self):
        self.O.engines = [e for e in self.O.engines if e is not self.runner]
        _LIVE.pop(self.label, None)


#: live checks by label (the PyRunner's command finds its object here)
_LIVE = {}
