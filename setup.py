"""Build of yade-electro's compiled kernels, at install (``pip install .``, or ``-e .`` in a
checkout: ``make install`` does it). The metadata is in pyproject.toml.

Each kernel in ``yade_electro/native/<name>.cpp`` becomes a shared library
``yade_electro/native/_<name>.<suffix>.so`` that :mod:`yade_electro.native.loader` loads with
ctypes (plain ``extern "C"`` functions: no Python API). The CGAL Delaunay helper is a program,
``yade_electro/native/delaunay_cgal``, built when CGAL's headers are there (else the Voronoi
tessellation uses scipy's qhull). A user's run never needs a compiler.
"""
import os
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

NATIVE = os.path.join("yade_electro", "native")
EIGEN = "/usr/include/eigen3"
CGAL_HEADER = "/usr/include/CGAL/Delaunay_triangulation_3.h"
BASE = ["-O2", "-std=c++17", "-DNDEBUG"]

#: kernel -> its own compiler flags (beside BASE)
KERNELS = {
    "graph_hops": [],
    "soft_spheres": ["-ffp-contract=off"],      # numpy's operations in numpy's order: the same bits
    "fire_steps": ["-pthread"],
    "laplacian_fill": [],
    "wall_contacts": [],
    "contact_radii": ["-ffp-contract=off"],
    "continuum_factors": [],
    "csr_pattern": [],
    "deflated_cg": ["-O3", f"-I{EIGEN}"],
}


class BuildKernels(build_ext):
    """build_ext that also builds the CGAL helper program, and says what failed and why."""

    def build_extension(self, ext):
        try:
            super().build_extension(ext)
        except Exception as exc:
            hint = " (apt-get install libeigen3-dev)" if "deflated_cg" in ext.name else ""
            sys.exit(f"yade-electro: building the compiled kernel {ext.name} failed{hint}: {exc}")

    def run(self):
        super().run()
        self.build_cgal()

    def build_cgal(self):
        src = os.path.join(NATIVE, "delaunay_cgal.cpp")
        out_dir = NATIVE if self.inplace else os.path.join(self.build_lib, NATIVE)
        target = os.path.join(out_dir, "delaunay_cgal")
        if not os.path.exists(CGAL_HEADER):
            print(f"yade-electro: CGAL headers not found ({CGAL_HEADER}): the Delaunay helper is not built, the "
                  "Voronoi tessellation will use scipy's qhull (apt-get install libcgal-dev for large packings)")
            return
        cc = self.compiler
        objs = cc.compile([src], output_dir=self.build_temp, extra_postargs=BASE)
        cc.link_executable(objs, "delaunay_cgal", output_dir=out_dir, libraries=["gmp", "mpfr"],
                           target_lang="c++")
        print(f"yade-electro: built {target}")


setup(
    ext_modules=[Extension(f"yade_electro.native._{name}", [os.path.join(NATIVE, f"{name}.cpp")],
                           extra_compile_args=BASE + flags, extra_link_args=[f for f in flags if f == "-pthread"],
                           language="c++")
                 for name, flags in KERNELS.items()],
    cmdclass={"build_ext": BuildKernels},
)
