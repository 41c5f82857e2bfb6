"""The vocabulary of Kirchhoff networks: the Laplacian, connected parts, electrodes, edge power.

See :mod:`yade_electro.network.conduction` for the sign conventions. Units: SI (S, V, A, W).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Dict, Optional

import numpy as np
import scipy.sparse as sp

from ..core.graph import connected_parts
from .boundary import TerminalRole, check_condition, terminal_number

__all__ = ["laplacian", "network_components", "electrode_value", "edge_power", "PotentialOrCurrent",
           "Electrode"]


def laplacian(edges, conductance, n_nodes: int) -> sp.csr_matrix:
    """K = A^T C A of a network [S]: symmetric, rows summing to zero.

    Parameters
    ----------
    edges : (m, 2) int array of node indices
    conductance : (m,) array of edge conductances [S], >= 0
    n_nodes : number of nodes
    """
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    c = np.asarray(conductance, dtype=float)
    if c.shape != (edges.shape[0],):
        raise ValueError(f"conductance must have one value per edge ({edges.shape[0]}), got {c.shape}")
    i, j = edges[:, 0], edges[:, 1]
    diag = np.bincount(i, c, n_nodes) + np.bincount(j, c, n_nodes)
    rows = np.concatenate([i, j, np.arange(n_nodes)])
    cols = np.concatenate([j, i, np.arange(n_nodes)])
    vals = np.concatenate([-c, -c, diag])
    return sp.csr_matrix((vals, (rows, cols)), shape=(n_nodes, n_nodes))


def network_components(n_nodes: int, edges, conducting=None) -> tuple:
    """(count, label per node) of the connected parts of a network, through the edges where
    ``conducting`` (default: all) is true."""
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if conducting is not None:
        edges = edges[np.asarray(conducting, bool)]
    return connected_parts(n_nodes, edges)


def electrode_value(name: str, value) -> float:
    """An electrode potential [V] or current [A] as a finite float, or BoundaryConditionError
    (the terminal's check, in electrical words)."""
    return terminal_number(PotentialOrCurrent, name, value)


def edge_power(branch_current, conductance) -> np.ndarray:
    """Power dissipated in each edge, w^2 / c [W]; 0 on edges of zero conductance (they
    carry no current)."""
    c = np.asarray(conductance, dtype=float)
    w = np.asarray(branch_current, dtype=float)
    return np.divide(w * w, c, out=np.zeros_like(c), where=c > 0)


class PotentialOrCurrent(TerminalRole):
    """What an electrode imposes, the same for every kind of electrode: a fixed ``potential``
    [V] or an imposed ``current`` [A] fed into the network, exactly one, a finite real number.
    The electrical name of a :class:`~yade_electro.network.boundary.Terminal`: checked by the
    terminal's one check (:meth:`check_value`, from the subclass's ``__post_init__``)."""

    KIND: ClassVar[str] = "electrode"
    FIELDS: ClassVar[Dict[str, str]] = {"value": "potential", "rate": "current"}
    UNITS: ClassVar[Dict[str, str]] = {"value": "V", "rate": "A"}

    def check_value(self):
        check_condition(self)

    @property
    def value(self) -> float:
        """The potential [V] or the current [A] (the terminal's :attr:`amount`)."""
        return self.amount


@dataclass(frozen=True)
class Electrode(PotentialOrCurrent):
    """A set of nodes tied by a perfect conductor, at a fixed potential or fed a current: the
    electrical name of :class:`~yade_electro.network.boundary.Terminal`.

    Parameters
    ----------
    name : str
    nodes : int array
        Node indices (not body ids; see ``ContactGraph.index_of``).
    potential : float, optional
        Fixed potential [V].
    current : float, optional
        Imposed total current [A] fed into the network (its potential is then an unknown).
        Give exactly one of ``potential`` and ``current``.
    """

    name: str
    nodes: np.ndarray
    potential: Optional[float] = None
    current: Optional[float] = None
