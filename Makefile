# yade-electro. Everything runs on Debian's /usr/bin/python3, the interpreter YADE is built for.
PY ?= /usr/bin/python3
YADE ?= yade-electro
PYTEST = $(PY) -m pytest -q -ra
# pytest exits 5 when it collected no test: that must not pass silently.
NO_TESTS = { echo "error: pytest collected no tests (exit 5); check tests/ and the -m filter" >&2; exit 1; }

.PHONY: install test test-fast lint docs demo bench

install:
	PY=$(PY) bash scripts/install.sh

# what CI runs: the install, the checks, the docs, then every test
test: install lint docs
	@$(PYTEST) tests; rc=$$?; [ $$rc -ne 5 ] || $(NO_TESTS); exit $$rc

# core tests only: no YADE, no LIGGGHTS, no install step
test-fast:
	@$(PYTEST) -m "not yade and not liggghts" --ignore=tests/test_install.py tests; rc=$$?; [ $$rc -ne 5 ] || $(NO_TESTS); exit $$rc

# ruff, and the layers contract of pyproject.toml (import-linter: no import from a lower layer
# to a higher one, none between independent ones, no YADE in the numerical core)
lint:
	$(PY) -m ruff check .
	$(PY) -c 'import sys; from importlinter.cli import lint_imports_command; sys.exit(lint_imports_command())'

# the docs site (Sphinx, numpydoc), warnings as errors, into docs/_build/html
docs:
	rm -rf docs/_api docs/_generated
	$(PY) docs/generate.py
	$(PY) -m sphinx -E -W --keep-going -q -b html docs docs/_build/html

# rod validation case (paper 000, section 3): both laws side by side
demo: install
	$(YADE) -n -x cases/rod_resistance.py --n 5000 --demo

bench: install
	@set -e; ls bench/*.py >/dev/null 2>&1 || { echo "error: no bench/*.py scripts" >&2; exit 1; }; \
	for f in bench/[!_]*.py; do echo "== $$f"; $(YADE) -n -x $$f; done
