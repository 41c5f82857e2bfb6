"""How the heat is advanced in time, and how it is coupled to the potential: one frozen object.

Units: SI (s, 1/K).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

from ..core.materials import real_number
from ..network.theta import theta_of

__all__ = ["Integrator", "MODEL_OPTIONS", "JOULE_SHARINGS", "joule_sharing_for"]

#: the ways of giving the network's Joule power to the elements (``Integrator(joule_sharing=)``)
JOULE_SHARINGS = ("auto", "edges", "cells")

#: the Integrator fields the coupled model takes besides theta, eta and the solver (the engines
#: keep the ones that differ from the default in their saved configuration)
MODEL_OPTIONS = ("subcycle", "safety", "max_substeps", "coupling_iterations", "coupling_tol", "resistivity_tol",
                 "joule_sharing")


@dataclass(frozen=True)
class Integrator:
    """The time integration of the heat network and its coupling to the electrical one.

    Parameters
    ----------
    theta : str or float
        ``'backward-euler'`` (default, theta = 1: unconditionally stable, no overshoot),
        ``'crank-nicolson'`` (1/2: second order, oscillates at steps far above the explicit
        limit), ``'explicit'`` (0: forward Euler, sub-cycled) or a number in [0, 1].
    dt : float, optional
        Thermal time step of each engine call [s]. Default: the simulated time elapsed since
        the previous call (``O.time`` difference) times ``time_scale``; either way it is not
        bound to ``O.dt``.
    time_scale : float
        Thermal seconds per mechanical second when ``dt`` is not given (default 1).
    steady : bool
        Each call solves the steady temperatures of that moment instead of a time step (the
        thermal clock does not move): for a solid whose heat settles faster than it moves.
    solver : str
        Linear solver of the implicit step (default ``'cg'``: Jacobi-CG on the temperature
        change, warm-started; ``'cg-deflated'``, ``'direct'``; see :mod:`yade_electro.solvers`).
    subcycle : bool
        For theta < 1/2, split a step above the stable one into equal sub-steps (default), or
        raise :class:`~yade_electro.core.errors.ThermalError`.
    safety : float in (0, 1]
        Fraction of the stability bound ``min_i C_i / sum_j G_ij`` [s] used as the largest
        (sub-)step (default 0.9). The engine reports the bound as ``critical_time_step`` and
        the sub-steps of the last call as ``substeps``.
    max_substeps : int
        Refuse a step that needs more explicit sub-steps than this (default 100,000).
    eta : float in [0, 1]
        Share of the electrical power released as heat (paper 000 eq. 11; default 1).
    joule_sharing : str
        How the network's Joule power is given to the elements. ``'auto'`` (default):
        ``'cells'`` under the ``'voronoi'`` law (a bonded solid read as a continuum),
        ``'edges'`` under every other law. ``'edges'``: each link's ``w^2 / c`` half and half
        to its two ends (the heat of a granular contact is made at the contact). ``'cells'``:
        each element gets ``V_i |g_i|^2 / rho_i``, its cell's volume times the field
        reconstructed at it (the least-squares gradient of the potential over its network
        neighbours, exact in a uniform field), scaled so the total is the network's power.
        With half-and-half sharing a cell in a uniform field gets 0.68-1.25 times its
        volume's share (the split follows its faces' orientations), which shows in local
        temperatures before conduction evens it out (``cases/narrow_ligament.py``: -7 % at
        0.5 ms with ``'edges'``, -1.4 % with ``'cells'``). Distributed runs do it too (each
        rank from its ghosts' potentials, the total summed over the ranks).
    coupling_iterations : int
        0 (default): the Joule sources of a step use the resistivity at its start (first order
        in dt). k > 0: the potential is re-solved up to k times with rho_e at the mid-step
        temperature (second order), until the sources change by less than ``coupling_tol``.
    coupling_tol : float
        Relative change of the sources that ends the coupling iterations (default 1e-10).
    resistivity_tol : float
        Re-solve the potential only when some element's rho_e(T) moved by more than this
        (relative) since the last solve (default 0: whenever it changed).

    Raises
    ------
    ValueError
        A theta that is not a known name or a number in [0, 1]; a step, scale or safety out
        of range.
    """

    theta: Any = "backward-euler"
    dt: Optional[float] = None
    time_scale: float = 1.0
    steady: bool = False
    solver: str = "cg"
    subcycle: bool = True
    safety: float = 0.9
    max_substeps: int = 100000
    eta: float = 1.0
    coupling_iterations: int = 0
    coupling_tol: float = 1e-10
    resistivity_tol: float = 0.0
    joule_sharing: str = "auto"

    def __post_init__(self):
        theta_of(self.theta)
        if self.dt is not None:
            dt = real_number("Integrator dt (s)", self.dt)
            if not dt > 0:
                raise ValueError(f"Integrator dt must be > 0 (s), got {self.dt}")
            object.__setattr__(self, "dt", dt)
        if not real_number("Integrator time_scale", self.time_scale) > 0:
            raise ValueError(f"Integrator time_scale must be > 0, got {self.time_scale}")
        for name in ("steady", "subcycle"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"Integrator {name} must be True or False, got {getattr(self, name)!r}")
        if not 0.0 < real_number("Integrator safety", self.safety) <= 1.0:
            raise ValueError(f"Integrator safety must be in (0, 1], got {self.safety}")
        if not 0.0 <= real_number("Integrator eta", self.eta) <= 1.0:
            raise ValueError(f"Integrator eta must be in [0, 1], got {self.eta}")
        joule_sharing_for(self.joule_sharing, "voronoi")         # a known name
        for name in ("max_substeps", "coupling_iterations"):
            v = getattr(self, name)
            if isinstance(v, bool) or int(v) != v or v < (1 if name == "max_substeps" else 0):
                raise ValueError(f"Integrator {name} must be an integer >= {1 if name == 'max_substeps' else 0}, "
                                 f"got {v!r}")

    @property
    def theta_value(self) -> float:
        """theta as a number in [0, 1]."""
        return theta_of(self.theta)

    def joule_sharing_for(self, law_name: str) -> str:
        """``'edges'`` or ``'cells'``: the sharing used under the conduction law named
        ``law_name`` (``'auto'`` is ``'cells'`` under ``'voronoi'``, ``'edges'`` otherwise)."""
        return joule_sharing_for(self.joule_sharing, law_name)


def joule_sharing_for(sharing: str, law_name: str) -> str:
    """``'edges'`` or ``'cells'``: what ``sharing`` (one of :data:`JOULE_SHARINGS`) means
    under the conduction law named ``law_name``; ValueError for an unknown sharing."""
    if sharing not in JOULE_SHARINGS:
        raise ValueError(f"joule_sharing must be 'auto' (cells under the voronoi law, edges otherwise), 'edges' "
                         f"(each link's Joule heat half and half to its ends) or 'cells' (from the field over each "
                         f"element's cell), got {sharing!r}")
    if sharing != "auto":
        return sharing
    return "cells" if law_name == "voronoi" else "edges"
