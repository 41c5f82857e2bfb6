"""Steady electrical conduction: div(grad(V) / rho) = 0 with electrodes at fixed potential.

The rest of the boundary is insulated (zero normal current). Electrode currents are taken
from the residual of the assembled system at the electrode dofs, r = K u: this is the
current the discrete solution actually carries (it is conserved to round-off and equals the
Joule power u^T K u / dV for two electrodes), and it is exact for fields the elements
represent exactly (P1 and a linear potential), where a flux integral of grad V at the faces
would only be as good as the gradient.
"""
from __future__ import annotations

import logging
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.sparse.linalg import splu
from skfem import Basis, BilinearForm, ElementTetP1, ElementTetP2, LinearForm, asm
from skfem.helpers import dot, grad

from ..core.errors import BoundaryConditionError, MaterialError, SolverError
from .probing import line_points, probe_matrix

__all__ = ["solve_potential", "PotentialSolution", "make_basis", "field_at_quadrature",
           "DirichletSolver"]

logger = logging.getLogger(__name__)

_ELEMENTS = {1: ElementTetP1, 2: ElementTetP2}


def make_basis(mesh, order: int = 1) -> Basis:
    """Lagrange basis of ``order`` 1 or 2 on a tetrahedral mesh."""
    if order not in _ELEMENTS:
        raise ValueError(f"order must be 1 (P1) or 2 (P2), got {order!r}")
    return Basis(mesh, _ELEMENTS[order]())


def field_at_quadrature(basis, value, name: str) -> np.ndarray:
    """A positive material property at the quadrature points, shape (nelems, nqp).

    ``value`` is a float, an array per element (nelems,), an array (nelems, nqp), or a
    callable of the quadrature-point coordinates x (3, nelems, nqp).
    """
    nel, nqp = basis.dx.shape
    if callable(value):
        q = np.asarray(value(np.asarray(basis.global_coordinates())), dtype=float)
    else:
        q = np.asarray(value, dtype=float)
    if q.ndim == 0:
        q = np.full((nel, nqp), float(q))
    elif q.shape == (nel,):
        q = np.repeat(q[:, None], nqp, axis=1)
    elif q.shape != (nel, nqp):
        raise MaterialError(f"{name} must be a number, an array per element ({nel},) or per "
                            f"quadrature point ({nel}, {nqp}); got shape {q.shape}")
    bad = ~np.isfinite(q) | (q <= 0)
    if np.any(bad):
        raise MaterialError(f"{name} must be positive and finite; {int(bad.sum())} quadrature "
                            f"values are not (min {np.nanmin(q):.3g})")
    return q


@BilinearForm
def _diffusion(u, v, w):
    return w["k"] * dot(grad(u), grad(v))


@BilinearForm
def _mass(u, v, w):
    return w["c"] * u * v


@LinearForm
def _source(v, w):
    return w["q"] * v


def dirichlet_dofs(basis, values: dict) -> tuple:
    """Dofs and values of named boundaries held at given values.

    Returns
    -------
    groups : dict name -> ndarray of dofs (a dof shared by two tags goes to the first)
    D : ndarray of all constrained dofs
    xD : ndarray of their values

    Raises
    ------
    BoundaryConditionError
        Unknown or empty tag, or a dof shared by two tags with different values.
    """
    known = sorted((basis.mesh.boundaries or {}).keys())
    groups, owner = {}, {}
    for name, value in values.items():
        if name not in known:
            raise BoundaryConditionError(f"unknown boundary {name!r}; this mesh has {known}")
        if not np.isfinite(value):
            raise BoundaryConditionError(f"value on {name!r} is not finite: {value!r}")
        dofs = basis.get_dofs(name).all()
        if dofs.size == 0:
            raise BoundaryConditionError(f"boundary {name!r} selects no dof")
        new = []
        for d in dofs:
            if d in owner:
                other = owner[d]
                if values[other] != value:
                    raise BoundaryConditionError(
                        f"boundaries {other!r} ({values[other]}) and {name!r} ({value}) touch "
                        "and have different values: the field would be discontinuous; "
                        "separate them or give them the same value")
            else:
                owner[d] = name
                new.append(d)
        groups[name] = np.asarray(new, dtype=np.int64)
    D = np.concatenate(list(groups.values())) if groups else np.zeros(0, np.int64)
    xD = np.concatenate([np.full(len(g), values[n], float) for n, g in groups.items()]) \
        if groups else np.zeros(0)
    return groups, D, xD


class DirichletSolver:
    """Factorised A_II of a sparse matrix A with dofs D eliminated; solve(b, xD) -> x.

    The factorisation (SuperLU) is kept, so a time loop with a constant matrix pays it once.
    """

    def __init__(self, A, D: np.ndarray):
        n = A.shape[0]
        self.A = A.tocsr()
        self.D = np.asarray(D, dtype=np.int64)
        mask = np.ones(n, dtype=bool)
        mask[self.D] = False
        self.I = np.nonzero(mask)[0]
        if self.I.size == 0:  # e.g. one layer of P1 between two electrodes
            self._lu = None
            return
        self._AII = self.A[self.I][:, self.I].tocsc()
        self._AID = self.A[self.I][:, self.D]
        try:
            self._lu = splu(self._AII)
        except RuntimeError as exc:
            raise SolverError(f"the system is singular ({exc}): a region without a "
                              "boundary condition (pure Neumann)?") from exc

    def solve(self, b: np.ndarray, xD: np.ndarray) -> np.ndarray:
        """Solution x of A x = b at the free dofs, with x[D] = xD."""
        x = np.zeros(self.A.shape[0])
        x[self.D] = xD
        if self._lu is None:
            return x
        x[self.I] = self._lu.solve(b[self.I] - self._AID @ x[self.D])
        if not np.all(np.isfinite(x)):
            raise SolverError("the linear solve produced nan/inf")
        return x


@dataclass(frozen=True)
class PotentialSolution:
    """Potential field and electrode currents.

    Attributes
    ----------
    basis : skfem.CellBasis
    u : ndarray
        Potential at the dofs [V].
    conductivity : ndarray (nelems, nqp)
        1 / rho at the quadrature points [S/m].
    dirichlet : dict
        Electrode name -> potential [V].
    currents : dict
        Electrode name -> current entering the domain through it [A] (sums to ~0).
    stiffness : scipy.sparse matrix
        Assembled K (so that K u = 0 at free dofs).
    """

    basis: object
    u: np.ndarray
    conductivity: np.ndarray
    dirichlet: dict
    currents: dict
    stiffness: object = field(repr=False)

    @property
    def mesh(self):
        """The mesh."""
        return self.basis.mesh

    @property
    def ndofs(self) -> int:
        """Number of degrees of freedom."""
        return int(self.basis.N)

    def equivalent_resistance(self, tag_a: str, tag_b: str) -> float:
        """R_eq = (V_a - V_b) / I_a [ohm], I_a the current entering through ``tag_a``.

        With more than two electrodes the other ones also carry current and R_eq is only
        the ratio above (a warning says so).
        """
        for tag in (tag_a, tag_b):
            if tag not in self.currents:
                raise BoundaryConditionError(f"{tag!r} is not an electrode; electrodes are "
                                             f"{sorted(self.currents)}")
        if len(self.currents) > 2:
            warnings.warn(f"{len(self.currents)} electrodes: R_eq between {tag_a!r} and "
                          f"{tag_b!r} is (V_a - V_b) / I_a with the others connected",
                          stacklevel=2)
        dv = self.dirichlet[tag_a] - self.dirichlet[tag_b]
        ia = self.currents[tag_a]
        if ia == 0.0:
            raise BoundaryConditionError(f"no current through {tag_a!r} (equal potentials?)")
        return float(dv / ia)

    def probe(self, points, tol: float = 1e-6) -> np.ndarray:
        """Potential [V] at points (npts, 3) or one point (3,) [m] (see ``find_cells``)."""
        x = _as_points(points)
        return probe_matrix(self.basis, x, tol) @ self.u

    def profile(self, start, end, n: int = 101) -> tuple:
        """Potential along the segment ``start``-``end``: (s [m], V [V])."""
        s, x = line_points(start, end, n)
        return s, self.probe(x.T)

    def power_density(self) -> np.ndarray:
        """Joule power density ``|grad V|^2 / rho`` at the quadrature points [W/m^3]."""
        g = self.basis.interpolate(self.u).grad
        return self.conductivity * np.sum(g * g, axis=0)

    def joule_power(self) -> float:
        """Total Joule power u^T K u = sum_a V_a I_a [W]."""
        return float(self.u @ (self.stiffness @ self.u))

    def joule_source(self, basis=None) -> np.ndarray:
        """Load vector of the Joule power density for ``basis`` (default: the same) [W]."""
        basis = self.basis if basis is None else basis
        if basis is not self.basis and basis.dx.shape != self.basis.dx.shape:
            raise ValueError("the thermal basis must share the potential basis' quadrature")
        return asm(_source, basis, q=self.power_density())


def _as_points(points) -> np.ndarray:
    """Points given as (npts, 3) (a sequence of points) or one point (3,) -> array (3, npts)."""
    x = np.asarray(points, dtype=float)
    if x.ndim == 1:
        x = x[None, :]
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"points must be a point (3,) or a sequence of points (npts, 3) "
                         f"[m]; got shape {x.shape}")
    return x.T


def solve_potential(mesh, rho, dirichlet: dict, order: int = 1, basis=None) -> PotentialSolution:
    """Steady conduction with electrodes at fixed potential, insulated elsewhere.

    Parameters
    ----------
    mesh : skfem.MeshTet
        Mesh with named boundaries (see ``yade_electro.fem.meshes``).
    rho : float, ndarray or callable
        Electrical resistivity [ohm m]: a number, per element, per quadrature point, or a
        callable of the coordinates (see :func:`field_at_quadrature`).
    dirichlet : dict
        Boundary name -> potential [V]; at least one, and two different values for a current.
    order : int
        1 (P1, exact for linear potentials) or 2 (P2).
    basis : skfem.CellBasis, optional
        Reuse an existing basis on ``mesh`` (``order`` is then ignored).

    Returns
    -------
    PotentialSolution
    """
    if not dirichlet:
        raise BoundaryConditionError("give at least one electrode: dirichlet={'name': V}")
    basis = make_basis(mesh, order) if basis is None else basis
    sigma = 1.0 / field_at_quadrature(basis, rho, "rho")
    K = asm(_diffusion, basis, k=sigma)
    groups, D, xD = dirichlet_dofs(basis, dirichlet)
    u = DirichletSolver(K, D).solve(np.zeros(basis.N), xD)
    r = K @ u
    currents = {name: float(np.sum(r[g])) for name, g in groups.items()}
    total = sum(currents.values())
    scale = max(abs(c) for c in currents.values()) or 1.0
    if abs(total) > 1e-8 * scale:
        logger.warning("electrode currents sum to %.3g A (relative %.2g): poor solve?",
                       total, abs(total) / scale)
    logger.debug("potential: %d dofs, currents %s", basis.N, currents)
    return PotentialSolution(basis=basis, u=u, conductivity=sigma, dirichlet=dict(dirichlet),
                             currents=currents, stiffness=K)
