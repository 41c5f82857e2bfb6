"""Sphinx configuration of the yade-electro docs (``make docs``: warnings are errors)."""
import os
import sys

sys.path.insert(0, os.path.abspath(".."))

import yade_electro  # noqa: E402

project = "yade-electro"
author = "the yade-electro developers"
copyright = "the yade-electro developers, GPL-2.0-or-later"
version = release = yade_electro.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "results", "img/README*"]
templates_path = ["_templates"]

# the API reference: one page per module, from the numpydoc docstrings of every public name
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_mock_imports = ["yade", "petsc4py", "mpi4py", "gmsh"]
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks = set()

myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3

html_theme = "alabaster"
html_static_path = []
html_title = f"yade-electro {version}"
html_theme_options = {"description": "Conduction, Joule heating and heat in DEM packings, for YADE",
                      "fixed_sidebar": True}
nitpicky = False
suppress_warnings = ["myst.header", "ref.python"]
