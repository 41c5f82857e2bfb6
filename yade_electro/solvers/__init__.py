"""Linear solvers behind one protocol ``solve(A, b, x0=None) -> (x, info)``, bound to a matrix
pattern with their setup kept: Jacobi-CG, deflated CG, AMG (PyAMG), PETSc, direct; a registry and
'auto'.
"""
from .amg import AMGSolver
from .base import (Solver, DirectSolver, relative_residual, check_converged, nonfinite_rhs, breakdown,
                   nonfinite_solution, nonpositive_diagonal)
from .cg import pcg, CGSolver
from .deflation import DeflatedCGSolver
from .petsc import PETScSolver, import_petsc, petsc_available, petsc4py_location
from .registry import make_solver, solver_names, auto_solver_name, check_solver_name, AUTO_DEFLATION_FROM

__all__ = ["AMGSolver", "Solver", "DirectSolver", "relative_residual", "check_converged", "nonfinite_rhs",
           "breakdown", "nonfinite_solution", "nonpositive_diagonal", "pcg", "CGSolver", "DeflatedCGSolver",
           "PETScSolver", "import_petsc", "petsc_available", "petsc4py_location", "make_solver",
           "solver_names", "auto_solver_name", "check_solver_name", "AUTO_DEFLATION_FROM"]
