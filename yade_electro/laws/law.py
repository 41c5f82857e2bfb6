"""The choice of a conductance law, as one small frozen object that engines and models take.

Units: m (the container), dimensionless volume fractions.
"""
from __future__ import annotations

from types import MappingProxyType
from typing import Any, Mapping, Optional

from .factors import check_law_name, make_law, needs_container

__all__ = ["Law"]


class Law:
    """A conductance law by name, with its parameters and the solid it is bounded by.

    Parameters
    ----------
    name : str or None
        ``'auto'`` or None (default: ``'voronoi'`` when the container is known, else ``'continuum'``;
        ``'contact'`` in a granular bed), or a name of :func:`~yade_electro.laws.conductance_laws`:
        ``'continuum'`` (paper 000's transmission surfaces), ``'voronoi'`` (bounded Voronoi
        faces), ``'contact'`` (2 a), ``'liggghts'`` (2 sqrt(pi) a), ``'pipe'``.
    container : Shape or YADE predicate, optional
        The solid the packing fills (the ``voronoi`` law's bound, and where surface conditions
        act). Default: the container :func:`~yade_electro.yade.bonding.add_bonded_packing` kept
        with the scene.
    volume_fraction : float, optional
        The elements' volume fraction for the heat capacities ``rho c V / fv`` (e.g. 1.0: each
        element carries its own sphere's capacity). Default: paper 000's ``fv(n)`` with
        ``'continuum'``, the bounded Voronoi cells with ``'voronoi'``, 1 in a granular bed.
    **params
        The law's own parameters, e.g. ``crack='facets'`` and ``hops=3`` (``'voronoi'``),
        ``threshold=0.4`` and ``factor=2`` (``'continuum'``), ``radius='hertz'``,
        ``stiffness_ratio=...`` and ``correction=...`` (contact laws), ``width`` (``'pipe'``).

    Raises
    ------
    KeyError
        An unknown law name (the message lists the known ones).
    ValueError
        A name that is not a string, or the container given twice.
    """

    __slots__ = ("name", "container", "volume_fraction", "params")

    def __init__(self, name: str = "auto", *, container: Any = None, volume_fraction: Optional[float] = None,
                 **params):
        if name is None:
            name = "auto"
        if not isinstance(name, str):
            raise ValueError(f"a law is given by its name (a string), got {name!r}")
        if name != "auto":
            check_law_name(name)
        if "container" in params:                 # make_law's spelling
            given = params.pop("container")
            if container is not None and given is not container:
                raise ValueError("give the container once, as Law(..., container=shape)")
            container = given
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "container", container)
        object.__setattr__(self, "volume_fraction", volume_fraction)
        object.__setattr__(self, "params", MappingProxyType(dict(params)))

    def __setattr__(self, key, value):
        raise AttributeError("a Law is frozen: make a new one")

    def __reduce__(self):
        return (_law, (self.name, self.container, self.volume_fraction, dict(self.params)))

    def __repr__(self):
        extra = "".join(f", {k}={v!r}" for k, v in self.params.items())
        if self.container is not None:
            extra += f", container={self.container!r}"
        if self.volume_fraction is not None:
            extra += f", volume_fraction={self.volume_fraction!r}"
        return f"Law({self.name!r}{extra})"

    @classmethod
    def of(cls, law) -> "Law":
        """A Law from a Law or a law name."""
        if isinstance(law, Law):
            return law
        if law is None:
            return cls()
        return cls(law)

    def make(self, default: str = "continuum"):
        """The conductance law object (:func:`~yade_electro.laws.make_law`); ``default`` for
        ``'auto'``; the container goes to the laws bounded by it."""
        name = default if self.name == "auto" else self.name
        params = dict(self.params)
        if self.container is not None and needs_container(name):
            params["container"] = self.container
        return make_law(name, **params)

    @property
    def law_params(self) -> Mapping[str, Any]:
        """The parameters :func:`~yade_electro.laws.make_law` takes (with the container)."""
        out = dict(self.params)
        if self.container is not None:
            out["container"] = self.container
        return out


def _law(name, container, volume_fraction, params):
    return Law(name, container=container, volume_fraction=volume_fraction, **params)
