"""Finding and importing YADE.

Debian's ``yade`` package installs its Python modules under
``/usr/lib/<triplet>/yade-<flavour>/py`` and links them into ``dist-packages`` through a
symlink that is broken in Debian 12, so a plain ``import yade`` from ``/usr/bin/python3``
fails. :func:`import_yade` adds the right directory to ``sys.path`` when needed.
Inside the ``yade`` launcher (``yade script.py``) YADE is already imported and nothing is
changed.
"""
import glob
import importlib
import os
import sys
import warnings

__all__ = ["import_yade", "in_yade", "yade_python_dirs", "MPY_REFUSAL", "in_mpy_subdomain", "mpy_subdomain"]

#: Directories tried first, in order; the double-precision build is the default ``yade``.
PREFERRED_DIRS = (
    "/usr/lib/x86_64-linux-gnu/yade-double/py",
    "/usr/lib/x86_64-linux-gnu/yade/py",
)

INSTALL_HINT = (
    "YADE is needed here. Install it with `make install` in the yade-electro repository "
    "(or `apt-get install yade` on Debian/Ubuntu), and run on Debian's /usr/bin/python3 "
    "(or inside `yade script.py`): YADE's compiled modules load only in the interpreter "
    "they were built for, not in a pyenv/conda Python."
)


def in_yade():
    """Return True when YADE is already imported, e.g. inside ``yade script.py``."""
    return "yade" in sys.modules


def _flavour_rank(path):
    # double precision first, then the plain name, then the others (long double, mpfr...)
    name = os.path.basename(os.path.dirname(path))
    return (name != "yade-double", name != "yade", path)


def yade_python_dirs():
    """Existing directories that hold YADE's ``yade`` Python package, most likely first."""
    globbed = glob.glob("/usr/lib/*/yade*/py") + glob.glob("/usr/lib/yade*/py")
    found = list(PREFERRED_DIRS) + sorted(globbed, key=_flavour_rank)
    dirs = []
    for d in found:
        if d not in dirs and os.path.isfile(os.path.join(d, "yade", "__init__.py")):
            dirs.append(d)
    return dirs


def import_yade():
    """Import and return the ``yade`` module.

    Uses the module already imported (inside the ``yade`` launcher), then a plain import,
    then the first directory of :func:`yade_python_dirs` appended to ``sys.path`` (only
    one: two YADE builds must not be loaded into one process).

    Raises
    ------
    ImportError
        If YADE is not installed or cannot be loaded by this interpreter; the message says
        how to install it and which interpreter to use.
    """
    if in_yade():
        return sys.modules["yade"]
    errors = []
    for d in [None] + yade_python_dirs()[:1]:
        added = d is not None and d not in sys.path
        if added:
            sys.path.append(d)
        try:
            with warnings.catch_warnings():  # YADE's own modules: invalid escape sequences
                warnings.simplefilter("ignore", DeprecationWarning)
                return importlib.import_module("yade")
        except ImportError as exc:
            errors.append("%s: %s" % (d or "import yade", exc))
            for name in [m for m in sys.modules if m == "yade" or m.startswith("yade.")]:
                del sys.modules[name]
            if added:
                sys.path.remove(d)
    if len(errors) == 1:
        errors.append("no directory /usr/lib/*/yade*/py holds a `yade` package")
    raise ImportError("%s\nTried with %s:\n  %s"
                      % (INSTALL_HINT, sys.executable, "\n  ".join(errors)))


MPY_REFUSAL = ("engine {label!r}: this scene is a subdomain of yade.mpy's decomposition (O.subD is set) and the "
               "engine was built for a serial solve: it would see only this rank's bodies. Build it with "
               "solver='petsc' (before mp.mpirun): it then runs distributed on yade.mpy's subdomains")


def mpy_subdomain():
    """yade.mpy's Subdomain of this rank once it has split the scene (it sets ``O.subD`` on its
    own Omega handle when ``mpirun`` starts), else None."""
    mpy = sys.modules.get("yade.mpy")
    return None if mpy is None else getattr(getattr(mpy, "O", None), "subD", None)


def in_mpy_subdomain() -> bool:
    """True when yade.mpy has split the scene into subdomains (plain ``mpiexec`` runs without
    mpirun do not)."""
    return mpy_subdomain() is not None


# =========================================================================================
