"""The steady state of the heat network, ``M T = s`` (part of
:class:`~yade_electro.network.transient.HeatSolver`, a mixin of its class): the floating parts'
policy (:mod:`.floating`), the check an engine makes when it is built, the kept iterative
solver, and the direct solve a failed iterative one falls back to.

Units: SI (W, K, W/K).
"""
from __future__ import annotations

import logging
import warnings

import numpy as np

from ..core.errors import SolverError, ThermalError
from ..solvers.base import DirectSolver
from ..solvers.registry import make_solver
from .floating import floating_parts, solve_with_floating
from .records import SteadyHeat, read_only_copy as _ro

__all__ = ["SteadyHeatSolve"]

log = logging.getLogger(__name__)


class SteadyHeatSolve:
    """The steady solve of :class:`~yade_electro.network.transient.HeatSolver` (whose
    structure, ``_Muu``, ``_u`` and ledger it uses: a part of that class kept in a module of
    its own)."""

    def _floating_unknowns(self, heat_in):
        """(labels, floating mask) of the unknowns that reach no fixed temperature, no link and
        no convection, by the policy of :mod:`.floating` (None when every part is anchored)."""
        anchored = self.h_area[self._u] > 0
        if self._Mud is not None and self._Mud.shape[1]:
            anchored = anchored | (np.asarray(abs(self._Mud).sum(axis=1)).ravel() > 0)
        return floating_parts(self._Muu, anchored, heat_in, reached="fixed temperature and no convection",
                              kept="their mean temperature (their heat)", inflow_name="heat (sources or fluxes)",
                              remedy="Add a FixedTemperature or a Convection there, or integrate in time (advance)",
                              error=ThermalError, stacklevel=5,
                              names=None if self.graph is None else self.graph.ids[self._u],
                              alone_remedy=self.alone_remedy)

    def check_steady(self, sources=None) -> None:
        """ThermalError now when a part that receives heat (``sources`` [W per node], the
        fluxes and heat sources of this solver) reaches no fixed temperature and no convection:
        :meth:`steady` would fail there (engines call it when they are built)."""
        src = np.zeros(self.n) if sources is None else np.asarray(sources, dtype=float)
        u = self._u
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")           # (floating parts with nothing coming in: said at the solve)
            self._floating_unknowns(src[u] + self.flux_power[u])

    #: the most unknowns a steady solve that the iterative solver did not bring to its tolerance
    #: is done again directly (sparse LU) instead of failing
    DIRECT_FALLBACK_UNKNOWNS = 300_000

    def _steady_directly(self, rhs, exc):
        """(T_u, info) of the steady system by sparse LU, after the iterative solver failed with
        ``exc`` (e.g. a tolerance of 1e-12 out of reach when the heat crosses a few weak links,
        such as grains' contact resistances, between stiff parts); ThermalError when the system
        is too large for it or the direct solve is off too."""
        n = self._Muu.shape[0]
        if n > self.DIRECT_FALLBACK_UNKNOWNS:
            raise ThermalError(f"the steady heat solve failed ({exc}); the temperatures are unchanged") from exc
        try:
            Tu, info = DirectSolver().solve(self._Muu, rhs)
        except (SolverError, RuntimeError, ArithmeticError) as exc2:
            raise ThermalError(f"the steady heat solve failed ({exc}; directly: {exc2}); the temperatures are "
                               "unchanged") from exc
        if not info["residual"] <= 1e-9:
            raise ThermalError(f"the steady heat solve failed ({exc}; directly: relative residual "
                               f"{info['residual']:.3g}); the temperatures are unchanged") from exc
        log.warning("steady heat solve: %s; solved directly instead (%d unknowns, relative residual %.2g)", exc, n,
                    info["residual"])
        return Tu, info

    def steady(self, sources=None, apply: bool = True, rtol: float = 1e-12) -> SteadyHeat:
        """The steady temperatures ``M T = s`` with the given ``sources`` [W per node] (plus the
        fluxes, heat sources, convection and fixed temperatures of this solver); they replace
        the current temperatures when ``apply`` (the clock does not move). A part of the network
        that reaches no fixed temperature and no convection keeps its mean temperature when no
        heat goes into it (a warning), and raises ThermalError when some does: the policy of
        :mod:`yade_electro.network.floating`.

        The linear solver is ``'auto'`` (:func:`yade_electro.solvers.registry.auto_solver_name`: the
        deflated CG from 80 unknowns on), kept across calls, to ``rtol`` relative residual."""
        n = self.n
        src = np.zeros(n) if sources is None else np.asarray(sources, dtype=float)
        if src.shape != (n,) or not np.all(np.isfinite(src)):
            raise ThermalError(f"sources must be a finite ({n},) array (W per node)")
        u = self._u
        parts = self._floating_unknowns(src[u] + self.flux_power[u])
        Tg = self._fixed_group_values()
        rhs = src[u] + self.flux_power[u] + self._hAT[u]
        if Tg.size:
            rhs = rhs - self._Mud @ Tg
        T = self._T.copy()
        info = {"iterations": 0, "residual": 0.0}
        if parts is not None:
            try:
                T[u], info = solve_with_floating(self._Muu, rhs, T[u], self._Cu, parts, rtol)
            except (SolverError, RuntimeError, ArithmeticError) as exc:
                raise ThermalError(f"the steady heat solve failed ({exc}); the temperatures are unchanged") from exc
        elif u.size:
            if getattr(self, "_steady_solver", None) is None or self._steady_key != id(self.system):
                self._steady_solver = make_solver("auto", n_unknowns=u.size, rtol=rtol)
                if self.coords is not None:
                    self._steady_solver.set_geometry(self.coords[u], self._mean_length(self.edges))
                self._steady_key = id(self.system)
                self._steady_A = None
            if self._steady_A is None:
                self._steady_A = self._Muu.copy()
            else:
                self._steady_A.data[:] = self._Muu.data
                self._steady_solver.update(self._steady_A)
            try:
                Tu, info = self._steady_solver.solve(self._steady_A, rhs, x0=T[u])
            except SolverError as exc:
                Tu, info = self._steady_directly(rhs, exc)
            except (RuntimeError, ArithmeticError) as exc:
                raise ThermalError(f"the steady heat solve failed ({exc}); the temperatures are unchanged") from exc
            if not np.all(np.isfinite(Tu)):
                raise ThermalError("the steady heat solve gave non-finite temperatures; the temperatures are "
                                   "unchanged (check the sources and conductances)")
            T[u] = Tu
        Tu = T[u]
        boundary = float(np.sum(self.system.group_flux(Tu, Tg))) if self._d.size else 0.0
        boundary += float(np.sum(self._link_GT[u] - self._link_G[u] * Tu))
        mask = np.zeros(n, bool)
        if parts is not None:
            mask[u[parts[1]]] = True
        mask.setflags(write=False)
        out = SteadyHeat(temperature=_ro(T), source_power=float(np.sum(src[u])),
                         flux_power=float(np.sum(self.flux_power[u])),
                         convection_power=float(np.sum(self._conv_hAT[u] - self._conv_hA[u] * Tu)),
                         boundary_power=boundary, iterations=int(info.get("iterations", 0)),
                         residual=float(info.get("residual", 0.0)), floating=mask)
        if apply:
            self._T = T
            self._dT_prev = None
        return out
