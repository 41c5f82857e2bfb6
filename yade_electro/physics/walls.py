"""The contacts of the walls of a granular bed, kept in one place for the electrical and the
thermal models: which spheres touch each wall, with what overlap, given before each step.

Units: m (overlaps), m (geometric factors).
"""
from __future__ import annotations

from typing import Dict, Iterable, Tuple

import numpy as np

from ..core.errors import BoundaryConditionError
from ..geometry.contacts import new_wall_contacts

__all__ = ["WallContacts"]


class WallContacts:
    """The spheres touching each named wall (node indices of the next graph) and their
    overlaps [m]; ``what`` names the walls in messages (e.g. ``'wall electrode'``)."""

    def __init__(self, names: Iterable[str], what: str = "wall"):
        self.what = what
        self._contacts: Dict[str, Tuple[np.ndarray, np.ndarray]] = {
            name: (np.zeros(0, dtype=np.int64), np.zeros(0)) for name in names}

    @property
    def names(self) -> list:
        return list(self._contacts)

    def __contains__(self, name) -> bool:
        return name in self._contacts

    def set(self, name: str, nodes, overlap) -> bool:
        """The contacts of wall ``name`` now; True when they changed. BoundaryConditionError for
        an unknown wall, ValueError for overlaps that are not finite, >= 0, one per node."""
        if name not in self._contacts:
            raise BoundaryConditionError(f"no {self.what} named {name!r}; have {sorted(self._contacts)}")
        new = new_wall_contacts(f"{self.what} {name!r}", self._contacts[name], nodes, overlap)
        if new is None:
            return False
        self._contacts[name] = new
        return True

    def contacts(self, name: str) -> Tuple[np.ndarray, np.ndarray]:
        """(nodes, overlaps [m]) of wall ``name``."""
        return self._contacts[name]

    def factors(self, name: str, law, radius, n_nodes: int) -> Tuple[np.ndarray, np.ndarray]:
        """(nodes, geometric factors g [m]) of wall ``name``'s contacts by ``law``'s
        sphere-wall factor, for the spheres of ``radius`` [m] (n_nodes of them)."""
        nd, dl = self._contacts[name]
        if nd.size and nd.max() >= n_nodes:
            raise ValueError(f"{self.what} {name!r}: contact node index beyond the graph's {n_nodes} nodes")
        return nd, law.wall_factor(np.asarray(radius)[nd], dl)
