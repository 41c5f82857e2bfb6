"""The structure every transport network shares, whatever it carries: nodes, edges and their
conductances checked once, the kept linear solver bound to the unknowns (with the node
positions for a coarse space), and the rule that turns a new edge set into a value update
when it is a subset of the kept one.

The two ways of solving a network build on it (:mod:`yade_electro.network.terminals`: steady
solves with terminals held at values or fed rates, the electrical networks;
:mod:`yade_electro.network.transient`: the theta method and steady solves with fixed values,
Robin terms and links, the heat networks). A physics says only what its numbers are called
(``WORDS``) and what a conductance is.

Units: SI, as the physics says (S or W/K).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..core.errors import MaterialError
from ..core.graph import edge_slots
from ..solvers.registry import make_solver

__all__ = ["Words", "GENERIC_WORDS", "NetworkStructure"]


@dataclass(frozen=True)
class Words:
    """How a physics names what flows in its messages.

    Attributes
    ----------
    conductance : str
        The message for conductances that are not finite and >= 0.
    """

    conductance: str = "conductances must be finite and >= 0"


#: the words of a network that carries no named physics
GENERIC_WORDS = Words()


class NetworkStructure:
    """Nodes, edges and conductances, checked once, and the linear solver kept for them.

    Subclasses call :meth:`_init_structure` first, and keep ``conductance`` up to date
    through :meth:`_check_conductance`. Attributes set here: ``n`` (nodes), ``edges``
    ((m, 2) int64), ``conductance`` ((m,) [S or W/K]), ``coords`` ((n, 3) [m] or None),
    ``structure_builds``.
    """

    WORDS: Words = GENERIC_WORDS

    def _init_structure(self, n_nodes: int, edges, conductance, solver, coords) -> None:
        self.n = n = int(n_nodes)
        edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
        if edges.size and (edges.min() < 0 or edges.max() >= n):
            raise ValueError(f"edge node index out of range 0..{n - 1}")
        self.edges = edges
        self.conductance = self._check_conductance(conductance)
        self.coords = None if coords is None else np.asarray(coords, dtype=float)
        self._solver_spec = solver
        self._solver = None
        self.structure_builds = 0

    def _check_conductance(self, conductance, m: Optional[int] = None) -> np.ndarray:
        """``conductance`` as a float array, one finite value >= 0 per edge (``m`` edges,
        default the kept ones), or ValueError / MaterialError."""
        m = self.edges.shape[0] if m is None else m
        c = np.asarray(conductance, dtype=float)
        if c.shape != (m,):
            raise ValueError(f"conductance must have one value per edge ({m}), got {c.shape}")
        if not np.all(np.isfinite(c)) or np.any(c < 0):
            raise MaterialError(self.WORDS.conductance)
        return c

    def _mean_length(self, edges) -> Optional[float]:
        """Mean length of ``edges`` [m] (None without edges): the spacing of a coarse space."""
        if edges.size == 0:
            return None
        d = self.coords[edges[:, 1]] - self.coords[edges[:, 0]]
        return float(np.mean(np.sqrt(np.einsum("ij,ij->i", d, d))))

    def _kept_solver(self, unknown_nodes, spacing_edges, **options):
        """The linear solver for ``unknown_nodes``: made again from its name at each new
        structure (a solver object given by the user is kept), and told where the unknowns
        are (``coords``) and how far apart (the mean length of ``spacing_edges``)."""
        nu = unknown_nodes.size
        if self._solver is None or isinstance(self._solver_spec, str):
            self._solver = make_solver(self._solver_spec, n_unknowns=nu, **options)
        if self.coords is not None and nu:
            self._solver.set_geometry(self.coords[unknown_nodes], self._mean_length(spacing_edges))
        return self._solver

    @property
    def solver(self):
        """The linear solver (kept while the structure is)."""
        return self._solver

    def _on_subset(self, edges, conductance):
        """The full conductance array when ``edges`` are a subset of the kept edges (a value
        update: the missing edges get conductance 0), else None (a new structure)."""
        slots = edge_slots(self.edges, edges, self.n)
        if slots is None:
            return None
        full = np.zeros(self.edges.shape[0])
        full[slots] = conductance
        return full
