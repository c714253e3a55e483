# The README's two commands: `make demo` (install, fly a Lynx campaign, plot its ellipses) and
# `make test` (install, run the tests). Both create the virtual environment they need.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
N ?= 1000

.PHONY: install demo test test-fast test-performance bench clean

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[test]"
	touch $@

install: $(VENV)/.installed

demo: install
	mkdir -p results
	$(VENV)/bin/rocketmc run campaigns/lynx_nominal.toml -n $(N) --out results/lynx_nominal.h5 --force  # the demo is meant to be rerun
	$(VENV)/bin/rocketmc report results/lynx_nominal.h5 --plot results/lynx_nominal_ellipses.png

test: install  # the correctness tests on two processes; the timing ratios are test-performance's
	$(PY) -m pytest -n 2 -q -m "not performance"

test-performance: install  # the timing ratios (-m performance) alone, on an otherwise idle machine (CI runs them)
	$(PY) -m pytest -q -m performance

test-fast: install  # the suite without the slow tests (-m slow) and the timing ones
	$(PY) -m pytest -n 2 -q -m "not slow and not performance"

bench: install
	$(VENV)/bin/rocketmc bench

clean:
	rm -rf results .pytest_cache
