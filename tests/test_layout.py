"""The shape of the package, checked: small modules in layer folders, a public name list in
every module, engines with few documented parameters. (The import layers themselves are
checked by ``make lint``: import-linter's contracts in pyproject.toml.)"""
import ast
import importlib
import inspect
import pkgutil
from pathlib import Path

import pytest

import yade_electro

PACKAGE = Path(yade_electro.__file__).parent
MAX_LINES, MAX_TOP_MODULES, MAX_ENGINE_PARAMETERS = 600, 8, 10


def _modules():
    return sorted(p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts)


def test_no_module_is_longer_than_600_lines():
    long = {str(p.relative_to(PACKAGE)): n for p in _modules() if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def test_few_modules_sit_directly_in_the_package():
    top = [p.name for p in PACKAGE.glob("*.py") if p.name not in ("__init__.py", "__main__.py")]
    assert len(top) <= MAX_TOP_MODULES, top


def test_every_public_module_lists_its_public_names():
    missing = []
    for p in _modules():
        rel = p.relative_to(PACKAGE)
        if any(part.startswith("_") and part != "__init__.py" for part in rel.parts) or p.name == "__main__.py":
            continue
        tree = ast.parse(p.read_text())
        if not any(isinstance(n, (ast.Assign, ast.AugAssign)) and "__all__" in ast.unparse(n).split("=")[0]
                   for n in tree.body):
            missing.append(str(rel))
    assert not missing, f"modules without __all__: {missing}"


def test_all_names_exist():
    for info in pkgutil.walk_packages([str(PACKAGE)], "yade_electro."):
        if info.name.endswith("__main__") or info.name.rsplit(".", 1)[1].startswith("_"):
            continue                    # the compiled kernels (_name.so) are loaded with ctypes
        mod = importlib.import_module(info.name)
        for name in getattr(mod, "__all__", ()):
            assert hasattr(mod, name), f"{info.name}.__all__ names {name!r}, which it does not have"


@pytest.mark.parametrize("name", ["ElectricalEngine", "ElectroThermalEngine", "HeatEngine", "ThermalExpansion"])
def test_engines_take_few_documented_keyword_parameters(name):
    from yade_electro import yade as Y
    cls = getattr(Y, name)
    params = [p for p in inspect.signature(cls.__init__).parameters.values() if p.name != "self"]
    assert len(params) <= MAX_ENGINE_PARAMETERS, [p.name for p in params]
    assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in params), "physics values are never positional"
    doc = inspect.getdoc(cls)
    for p in params:
        assert f"\n{p.name} :" in doc or f"\n{p.name}," in doc or f", {p.name}" in doc, f"{name}: {p.name} undocumented"
