"""Linear thermo-elasticity on the same meshes as the heat references (scikit-fem, P2).

Find the displacement u [m] with ``div sigma = 0``,

    sigma = lambda tr(eps) I + 2 mu eps - (3 lambda + 2 mu) alpha (T - T_ref) I,

``eps = sym(grad u)``; the thermal load is ``int (3 lambda + 2 mu) alpha dT div v``. Boundary
conditions: components of u set to zero on named facets (rollers: ``{"end0": (0,)}``), and the
rigid-body modes that remain removed by pinning single nodes (``pins``). The temperature is a
P1 field on the same mesh (e.g. :class:`~yade_electro.fem.thermal.ThermalResult`'s ``T``).

Units: SI (m, Pa, 1/K, K).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from skfem import Basis, ElementTetP1, ElementTetP2, ElementVector, LinearForm, asm, condense, solve
from skfem.helpers import div
from skfem.models.elasticity import lame_parameters, linear_elasticity

from ..core.errors import MaterialError

__all__ = ["ThermoElasticResult", "thermal_stress"]


@dataclass(frozen=True)
class ThermoElasticResult:
    """Displacements (at the nodes, (3, n_nodes) [m]) and stresses (per element, (n_el, 3, 3)
    [Pa], tension positive) of :func:`thermal_stress`."""

    mesh: object = field(repr=False)
    displacement: np.ndarray = field(repr=False)
    stress: np.ndarray = field(repr=False)
    volume: np.ndarray = field(repr=False)

    def centroids(self) -> np.ndarray:
        """Element centroids (n_el, 3) [m]."""
        return self.mesh.p[:, self.mesh.t].mean(axis=1).T

    def mean_stress_where(self, mask) -> np.ndarray:
        """Volume-weighted mean stress (3, 3) [Pa] of the elements in ``mask``."""
        m = np.asarray(mask, dtype=bool)
        if not np.any(m):
            raise ValueError("no element in the region")
        return np.einsum("e,eij->ij", self.volume[m], self.stress[m]) / self.volume[m].sum()

    def displacement_at(self, points) -> np.ndarray:
        """u (n, 3) [m] at points inside the mesh (P1 interpolation)."""
        from .probing import probe_matrix
        P = probe_matrix(Basis(self.mesh, ElementTetP1()), np.asarray(points, float).reshape(-1, 3).T, 1e-6)
        return np.column_stack([P @ self.displacement[k] for k in range(3)])


def thermal_stress(mesh, temperature, T_ref: float, young: float, poisson: float, alpha: float,
                   fixed: dict, pins=(), order: int = 2) -> ThermoElasticResult:
    """Solve the thermo-elastic problem of the module doc.

    Parameters
    ----------
    mesh : skfem.MeshTet with named boundaries
    temperature : (n_nodes,) [K], a P1 field
    T_ref : float [K]
    young, poisson, alpha : float [Pa], [-], [1/K]
    fixed : {boundary name: components (0, 1, 2) held at zero}
    pins : ((node index, components), ...) more single-node zero displacements
    order : 1 or 2, the displacement's elements (P2: exact for a linear temperature field)
    """
    if not (young > 0 and -1 < poisson < 0.5 and alpha >= 0):
        raise MaterialError(f"need E > 0, -1 < nu < 0.5, alpha >= 0; got {young}, {poisson}, {alpha}")
    T = np.asarray(temperature, dtype=float)
    if T.shape != (mesh.p.shape[1],) or not np.all(np.isfinite(T)):
        raise ValueError(f"temperature must be finite, one per node ({mesh.p.shape[1]})")
    lam, mu = lame_parameters(young, poisson)
    ib = Basis(mesh, ElementVector(ElementTetP2() if order == 2 else ElementTetP1()))
    tb = Basis(mesh, ElementTetP1(), quadrature=ib.quadrature)
    K = asm(linear_elasticity(lam, mu), ib)

    @LinearForm
    def load(v, w):
        return (3.0 * lam + 2.0 * mu) * alpha * w["dT"] * div(v)
    f = asm(load, ib, dT=tb.interpolate(T - T_ref))
    held = []
    for name, comps in fixed.items():
        dofs = ib.get_dofs(name)
        for c in comps:
            held.append(dofs.all(f"u^{c + 1}"))
    for node, comps in pins:
        for c in comps:
            held.append(np.array([ib.nodal_dofs[c, node]]))
    D = np.unique(np.concatenate(held)) if held else np.zeros(0, np.int64)
    u = solve(*condense(K, f, D=D))
    U = u[ib.nodal_dofs]                                # (3, n_nodes): the vertices' values
    # element means of sigma over the quadrature points (exact for P2 with a P1 temperature:
    # the strain and the thermal strain are both linear in an element)
    g = ib.interpolate(u).grad                          # (3, 3, n_el, n_qp): du_i/dx_j
    eps = 0.5 * (g + np.transpose(g, (1, 0, 2, 3)))
    dT = tb.interpolate(T - T_ref).value                # (n_el, n_qp)
    tr = eps[0, 0] + eps[1, 1] + eps[2, 2]
    I = np.eye(3)[:, :, None, None]
    sig = lam * tr * I + 2.0 * mu * eps - (3 * lam + 2 * mu) * alpha * dT * I
    dx = ib.dx                                          # (n_el, n_qp) weights
    vol = dx.sum(axis=1)
    sigma = np.einsum("ijeq,eq->eij", sig, dx) / vol[:, None, None]
    return ThermoElasticResult(mesh, U, sigma, vol)
