# yade-electro. Everything runs on Debian's /usr/bin/python3, the interpreter YADE is built for.
PY ?= /usr/bin/python3
YADE ?= yade-electro
PYTEST = $(PY) -m pytest -q -ra
# pytest exits 5 when it collected no test: that must not pass silently.
NO_TESTS = { echo "error: pytest collected no tests (exit 5); check tests/ and the -m filter" >&2; exit 1; }

.PHONY: install test test-fast demo bench

install:
	PY=$(PY) bash scripts/install.sh

test: install
	@$(PYTEST) tests; rc=$$?; [ $$rc -ne 5 ] || $(NO_TESTS); exit $$rc

# core tests only: no YADE, no LIGGGHTS, no install step
test-fast:
	@$(PYTEST) -m "not yade and not liggghts" --ignore=tests/test_install.py tests; rc=$$?; [ $$rc -ne 5 ] || $(NO_TESTS); exit $$rc

# rod validation case (paper 000, section 3): both laws side by side
demo: install
	$(YADE) -n -x cases/rod_resistance.py --n 5000 --demo

bench: install
	@set -e; ls bench/*.py >/dev/null 2>&1 || { echo "error: no bench/*.py scripts" >&2; exit 1; }; \
	for f in bench/[!_]*.py; do echo "== $$f"; $(YADE) -n -x $$f; done
