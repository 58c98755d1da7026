# whitted: the two Quick start commands are `make demo` and `make test`.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
# Compiled kernels are kept here between runs (see src/whitted/_cache.py).
export WHITTED_CACHE_DIR ?= $(CURDIR)/.cache

.PHONY: demo test test-timing lint install install-test bench clean

$(BIN)/whitted: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[all]'
	@touch $@

$(VENV)/.test-deps: $(BIN)/whitted
	$(BIN)/python -m pip install --quiet -e '.[test]'
	scripts/install-qt-deps.sh  # the system libraries Qt needs (the editor's tests), if missing
	@touch $@

install: $(BIN)/whitted

install-test: $(VENV)/.test-deps

## Install, then render the built-in default scene to render.png
demo: install
	$(BIN)/whitted render -o render.png

## Install the test dependencies, lint, then run the whole test suite
test: install-test
	$(BIN)/ruff check src tests
	$(BIN)/python -m pytest -q

## The tests whose outcome depends on the machine's speed (marker `timing`), run apart
test-timing: install-test
	$(BIN)/python -m pytest -q -m timing

## Render the benchmark scenes (benchmarks/) and print the timing table
bench: install
	$(BIN)/whitted bench

lint: install-test
	$(BIN)/ruff check src tests

clean:
	rm -rf $(VENV) .cache build *.egg-info src/*.egg-info
