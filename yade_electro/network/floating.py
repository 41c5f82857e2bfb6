"""The one policy for the parts of a network that reach no fixed value ("floating" parts), the
same for current and heat.

A connected part of a network *floats* when none of its nodes is held at a fixed value (a
fixed potential, a fixed temperature) or exchanges with one (a surface or wall link, a
convection to an ambient). Its level is then not set by the network:

* in a **steady** solve (a potential, a steady temperature), a floating part with **no net
  inflow** (no imposed current, no heat source or flux into it) keeps a reference level: 0 V
  for a potential, its own mean temperature (its heat content) for heat. It carries nothing to
  the rest, one warning says how many nodes in how many parts, and the results flag them
  (``PotentialSolution.floating``, ``SteadyHeat.floating``);
* a floating part **with** a net inflow has no steady state at all (the current or heat put in
  has nowhere to go): :class:`~yade_electro.core.errors.BoundaryConditionError` (current) or
  :class:`~yade_electro.core.errors.ThermalError` (heat), saying how many nodes and what to add;
* in a **transient** step (heat), a floating part is well defined: it keeps its heat plus what
  flows into it, and nothing is said.

Units: none.
"""
from __future__ import annotations

import warnings

import numpy as np
from scipy.sparse.csgraph import connected_components

from ..solvers.registry import make_solver

__all__ = ["floating_message", "warn_floating", "no_steady_state_message", "which_elements", "floating_parts",
           "hold_at_mean", "solve_with_floating"]


def floating_message(n_nodes: int, n_parts: int, reached: str, kept: str) -> str:
    """The warning for ``n_nodes`` floating nodes in ``n_parts`` parts: they reach no
    ``reached`` (e.g. 'electrode') and keep ``kept`` (e.g. 'a potential of 0 V')."""
    return (f"{n_nodes} element(s) in {n_parts} part(s) are connected to no {reached}: they carry nothing to the "
            f"rest and keep {kept} (see the results' floating mask)")


def warn_floating(n_nodes: int, n_parts: int, reached: str, kept: str, stacklevel: int = 3, detail: str = "") -> None:
    """Warn once about floating nodes (see :func:`floating_message`), with ``detail`` after."""
    warnings.warn(floating_message(n_nodes, n_parts, reached, kept) + detail, stacklevel=stacklevel)


def no_steady_state_message(n_nodes: int, n_parts: int, reached: str, inflow: str, remedy: str) -> str:
    """The error for floating parts with a net inflow: no steady state exists."""
    return (f"{n_nodes} element(s) in {n_parts} part(s) reach no {reached} but receive {inflow}: their steady state "
            f"is not defined ({inflow} has nowhere to go). {remedy}")


def which_elements(names, mask, labels=None, alone_remedy: str = "leave them out of the model",
                   limit: int = 10) -> str:
    """The words that name the elements of ``mask`` by ``names`` (their body ids; '' without
    names), and say how many stand alone (a part of one element: joined to nothing, e.g. a
    particle with no bond) and what to do with those (``alone_remedy``)."""
    if names is None or not np.any(mask):
        return ""
    ids = np.asarray(names)[np.asarray(mask, bool)]
    out = f" Bodies: {ids[:limit].tolist()}{' ...' if ids.size > limit else ''}."
    if labels is not None:
        lab = np.asarray(labels)[np.asarray(mask, bool)]
        _, count = np.unique(lab, return_counts=True)
        alone = int(np.sum(count == 1))
        if alone:
            out += f" {alone} of them stand alone, joined to nothing (a particle with no bond?): {alone_remedy}."
    return out


def floating_parts(matrix, anchored, inflow, *, reached: str, kept: str, inflow_name: str, remedy: str,
                   error=ValueError, stacklevel: int = 4, names=None, alone_remedy: str = "leave them out of the model"):
    """The floating unknowns of a network, by the policy above.

    Parameters
    ----------
    matrix : (m, m) sparse
        The unknowns' block of the network matrix: its non-zero entries give the connected
        parts (an edge kept in the structure with conductance 0, a contact that opened, joins
        nothing).
    anchored : (m,) bool
        Unknowns tied to a fixed value (a link, a convection, a fixed neighbour).
    inflow : (m,) float
        What each unknown receives from outside (A, W); any non-zero value in a floating part
        means it has no steady state.
    reached, kept, inflow_name, remedy : str
        The words of the warning and of the error.
    error : exception class
        Raised for a floating part with an inflow.
    names : (m,) optional
        The unknowns' body ids, to name the floating ones (:func:`which_elements`), and
        ``alone_remedy`` what to do with the ones joined to nothing.

    Returns
    -------
    (labels, floating) or None
        The connected part of each unknown and the mask of the floating ones; None when no
        part floats.
    """
    if matrix.shape[0] == 0:
        return None
    conducting = matrix.copy()
    conducting.data = (conducting.data != 0).astype(np.int8)
    conducting.eliminate_zeros()                 # csgraph takes stored zeros for edges
    n_parts, labels = connected_components(conducting, directed=False)
    anchor = np.zeros(n_parts, bool)
    np.logical_or.at(anchor, labels, np.asarray(anchored, bool))
    if np.all(anchor):
        return None
    fed = np.zeros(n_parts, bool)
    np.logical_or.at(fed, labels, np.asarray(inflow) != 0)
    bad = ~anchor & fed
    if np.any(bad):
        raise error(no_steady_state_message(int(np.sum(bad[labels])), int(np.sum(bad)), reached, inflow_name, remedy)
                    + which_elements(names, bad[labels], labels, alone_remedy))
    floating = ~anchor[labels]
    warn_floating(int(np.sum(floating)), int(np.sum(~anchor)), reached, kept, stacklevel=stacklevel,
                  detail=which_elements(names, floating, labels, alone_remedy))
    return labels, floating


def hold_at_mean(values, weights, labels, floating):
    """``values`` with each floating part set to its ``weights``-weighted mean (a heat
    content kept: weights are the capacities)."""
    out = np.array(values, dtype=float)
    for lab in np.unique(labels[floating]):
        part = labels == lab
        out[part] = float(np.sum(weights[part] * out[part]) / np.sum(weights[part]))
    return out


def solve_with_floating(matrix, rhs, x0, weights, parts, rtol: float):
    """Solve ``matrix x = rhs`` when some parts float (``parts`` from :func:`floating_parts`):
    each floating part is held at its ``weights``-weighted mean of ``x0``, the others are solved
    apart (they do not touch the floating parts) with a one-off ``'auto'`` solver. Returns
    (x, info); a non-finite result raises ArithmeticError."""
    labels, floating = parts
    x = hold_at_mean(x0, weights, labels, floating)
    rest = np.flatnonzero(~floating)
    info = {"iterations": 0, "residual": 0.0}
    if rest.size:
        sub = matrix[rest][:, rest].tocsr()
        xr, info = make_solver("auto", n_unknowns=rest.size, rtol=rtol).solve(sub, rhs[rest], x0=x[rest])
        if not np.all(np.isfinite(xr)):
            raise ArithmeticError("non-finite values; check the sources and conductances")
        x[rest] = xr
    return x, info
