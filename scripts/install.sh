#!/usr/bin/env bash
# Install everything yade-electro needs on Debian 12, then this package (editable).
#
#   scripts/install.sh             install what is missing (fast when nothing is)
#   scripts/install.sh --dry-run   only print what would be done
#
# Debian packages come from apt (YADE, LIGGGHTS, numpy, scipy, ...). The few Python packages
# Debian lacks come from PyPI, pinned and with --no-deps, into Debian's /usr/bin/python3 so
# that they import both there and inside `yade script.py` (the yade launcher runs that
# interpreter). pip never replaces Debian's numpy/scipy: YADE is built against them.
#
# Environment: PY (default /usr/bin/python3); YADE_ELECTRO_ASSUME_MISSING="name ..." treats
# those Debian/PyPI packages (and "yade-electro", the editable install) as missing, to show
# the fresh-machine plan with --dry-run (tests/test_install.py does).
set -euo pipefail
export DEBIAN_FRONTEND=noninteractive

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PY="${PY:-/usr/bin/python3}"

# Debian packages. python3-setuptools/-wheel: the editable install builds with them
# (--no-build-isolation, so pip fetches no setuptools from PyPI); it compiles the kernels of
# yade_electro/native (setup.py) with g++ and Eigen's headers (libeigen3-dev), and the CGAL
# Delaunay helper of the 'voronoi' law with libcgal-dev (without it, scipy's qhull is used).
# bench/bench_scale.py also builds an Eigen ConjugateGradient driver to compare the solves with.
# python3-petsc4py, python3-mpi4py, openmpi-bin: solver='petsc' and runs under mpiexec.
DEB_PACKAGES=(
  yade liggghts
  python3-pip python3-setuptools python3-wheel
  python3-numpy python3-scipy python3-pandas python3-matplotlib python3-pytest python3-meshio
  gmsh python3-gmsh
  g++ libeigen3-dev
  python3-petsc4py python3-mpi4py openmpi-bin
  libcgal-dev
  python3-threadpoolctl
  python3-click python3-typing-extensions
  python3-sphinx python3-numpydoc python3-myst-parser
)

# PyPI packages Debian 12 lacks, pinned to the newest release that declares support for
# Debian 12's scipy 1.10 / numpy 1.24 (checked with a solve in verify_python_stack):
# - pyamg 5.1.0: 5.2.x needs scipy>=1.11 (metadata), 5.3+ imports scipy.sparse.eye_array (1.12+).
# - scikit-fem 12.0.2: pure Python, requires only numpy and scipy.
# The checks of `make lint` (their other dependencies, click and typing-extensions, are Debian's):
# - ruff 0.8.6: a static binary; import-linter 2.1 with grimp 3.5 (a compiled wheel for cp311).
PIP_PINS=(pyamg==5.1.0 scikit-fem==12.0.2 ruff==0.8.6 import-linter==2.1 grimp==3.5)

DRY_RUN=0
for arg in "$@"; do
  case "$arg" in
    --dry-run|-n) DRY_RUN=1 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "install.sh: unknown argument '$arg' (try --help)" >&2; exit 2 ;;
  esac
done

say() { printf '[install] %s\n' "$*"; }
die() { printf '[install] ERROR: %s\n' "$*" >&2; exit 1; }
run() {  # print, then run unless --dry-run
  say "+ $*"
  if [ "$DRY_RUN" = 1 ]; then return 0; fi
  "$@"
}

SUDO=()
if [ "$(id -u)" != 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO=(sudo -n env DEBIAN_FRONTEND=noninteractive)
  elif [ "$DRY_RUN" = 0 ]; then die "not root and no sudo: run this script as root"; fi
fi

# ---------------------------------------------------------------- Debian packages
assumed_missing() { case " ${YADE_ELECTRO_ASSUME_MISSING:-} " in *" $1 "*) return 0 ;; esac; return 1; }
is_installed() {
  ! assumed_missing "$1" && [ "$(dpkg-query -W -f='${db:Status-Status}' "$1" 2>/dev/null)" = installed ]
}

missing=()
for pkg in "${DEB_PACKAGES[@]}"; do
  is_installed "$pkg" || missing+=("$pkg")
done
if [ "${#missing[@]}" = 0 ]; then
  say "Debian packages: all ${#DEB_PACKAGES[@]} present"
else
  command -v apt-get >/dev/null 2>&1 || die "apt-get not found: this script supports Debian 12 only"
  say "Debian packages missing: ${missing[*]}"
  run "${SUDO[@]}" apt-get update -q || die "apt-get update failed (network? Debian mirror?)"
  run "${SUDO[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}" \
    || die "apt-get install failed for: ${missing[*]}"
fi

# ---------------------------------------------------------------- Python interpreter
if [ "$DRY_RUN" = 1 ] && [ ! -x "$PY" ]; then
  say "(dry run: $PY not there yet, Python steps would follow)"; exit 0
fi
[ -x "$PY" ] || die "$PY not found: YADE runs on Debian's python3 (apt-get install python3)"
"$PY" -m pip --version >/dev/null 2>&1 || die "pip not available for $PY (apt-get install python3-pip)"

# numpy and scipy must be Debian's (YADE is built against them), never a pip copy.
check_debian_numpy() {
  "$PY" - <<'EOF' || die "numpy/scipy seen by $PY are not Debian's (see above): remove the pip copies with '$PY -m pip uninstall --break-system-packages numpy scipy'"
import numpy, scipy, sys
bad = [m for m in (numpy, scipy) if not m.__file__.startswith("/usr/lib/python3/dist-packages/")]
for m in bad:
    print("[install] %s %s comes from %s, not from Debian's package" % (m.__name__, m.__version__, m.__file__), file=sys.stderr)
sys.exit(1 if bad else 0)
EOF
}
check_debian_numpy

PIP=("${SUDO[@]}" "$PY" -m pip install --break-system-packages --no-input --disable-pip-version-check)

installed_version() {  # prints the installed version of a distribution, or nothing
  "$PY" -c 'import sys, importlib.metadata as m
try: print(m.version(sys.argv[1]))
except m.PackageNotFoundError: pass' "$1"
}

to_install=()
for pin in "${PIP_PINS[@]}"; do
  name="${pin%%==*}"; want="${pin##*==}"
  have="$(installed_version "$name")"
  assumed_missing "$name" && have=""
  if [ "$have" = "$want" ]; then
    say "PyPI: $name $have present"
  else
    say "PyPI: $name ${have:-not installed}, want $want"
    to_install+=("$pin")
  fi
done
if [ "${#to_install[@]}" -gt 0 ]; then
  # --no-deps: their only dependencies, numpy and scipy, are Debian's and must stay so.
  run "${PIP[@]}" --no-deps --only-binary=pyamg,ruff,grimp "${to_install[@]}" \
    || die "pip install failed for: ${to_install[*]}"
fi

# ---------------------------------------------------------------- this package, editable
editable_ok() {  # yade_electro importable from this checkout, its kernels built from their sources
  "$PY" - "$ROOT" <<'EOF'
import glob, importlib.machinery, importlib.util, os, sys
spec = importlib.util.find_spec("yade_electro")
root = os.path.realpath(sys.argv[1])
ok = spec is not None and spec.origin and os.path.realpath(spec.origin).startswith(root + os.sep)
native = os.path.join(root, "yade_electro", "native")
suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
for src in glob.glob(os.path.join(native, "*.cpp")):
    name = os.path.basename(src)[:-4]
    built = os.path.join(native, name if name == "delaunay_cgal" else f"_{name}{suffix}")
    if name == "delaunay_cgal" and not os.path.exists("/usr/include/CGAL/Delaunay_triangulation_3.h"):
        continue
    ok = ok and os.path.exists(built) and os.path.getmtime(built) >= os.path.getmtime(src)
sys.exit(0 if ok else 1)
EOF
}
# from / so that the checkout in the current directory does not count as installed
# the launcher (console script) comes with the editable install: reinstall when it is missing
if ! assumed_missing yade-electro && (cd / && PYTHONPATH='' editable_ok) && command -v yade-electro >/dev/null 2>&1; then
  say "yade-electro: editable install points at $ROOT, kernels built"
else
  say "yade-electro: installing $ROOT (editable, compiling its kernels: about 30 s) into $PY"
  run "${PIP[@]}" --no-deps --no-build-isolation -e "$ROOT" \
    || die "editable install of $ROOT failed"
fi

# ---------------------------------------------------------------- verify
[ "$DRY_RUN" = 1 ] && { say "dry run: nothing changed"; exit 0; }
check_debian_numpy
(cd / && PYTHONPATH='' "$PY" - <<'EOF') || die "the Python stack does not work (see the traceback above)"
import importlib.util
import numpy, scipy, pyamg, skfem
from skfem import Basis, ElementTetP1, MeshTet, condense, solve
from skfem.models.poisson import laplace, unit_load

A = pyamg.gallery.poisson((20, 20), format="csr")
b = numpy.ones(A.shape[0])
x = pyamg.smoothed_aggregation_solver(A).solve(b, tol=1e-10)
assert numpy.linalg.norm(b - A @ x) < 1e-6 * numpy.linalg.norm(b), "pyamg solve failed"

basis = Basis(MeshTet().refined(2), ElementTetP1())
u = solve(*condense(laplace.assemble(basis), unit_load.assemble(basis),
                    D=basis.mesh.boundary_nodes()))
assert 0.0 < u.max() < 0.1, "scikit-fem Poisson solve gave %r" % u.max()
# petsc4py: Debian puts it under /usr/lib/petscdir (yade_electro.solvers.petsc finds it). Found,
# not imported: importing it outside mpiexec starts an MPI singleton that listens on the network.
from yade_electro.solvers.petsc import petsc4py_location
petsc_dir = petsc4py_location()
assert petsc_dir, "petsc4py not found (apt-get install python3-petsc4py)"
# the compiled kernels and the CGAL Delaunay helper, built by the install
import glob, os
from yade_electro.native import cgal_executable
from yade_electro.native.loader import HERE, library_path
for src in sorted(glob.glob(os.path.join(HERE, "*.cpp"))):
    if not src.endswith("delaunay_cgal.cpp"):
        library_path(os.path.basename(src)[:-4])
cgal_executable()
print("[install] ok: numpy %s, scipy %s (Debian); pyamg %s, scikit-fem %s; petsc4py in %s; yade_electro from %s"
      % (numpy.__version__, scipy.__version__, pyamg.__version__, skfem.__version__, petsc_dir,
         importlib.util.find_spec("yade_electro").origin))
EOF
command -v yade >/dev/null 2>&1 || die "yade not on PATH after installing the Debian package"
command -v yade-electro >/dev/null 2>&1 || die "yade-electro (the launcher without open ports) not on PATH after the install"
command -v liggghts >/dev/null 2>&1 || die "liggghts not on PATH after installing the Debian package"
say "done"
