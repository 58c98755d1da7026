# whitted: the two Quick start commands are `make demo` and `make test`.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
# Compiled kernels are kept in the per-user cache (~/.cache/whitted, src/whitted/jit/cache.py),
# the one every later `whitted` command uses, however whitted was installed.

.PHONY: demo test test-oldest-numba test-timing check-wheel coverage lint install install-test bench clean

$(BIN)/whitted: pyproject.toml
	@echo "installing whitted and every extra into $(VENV)/ (about 1.3 GB: minutes on a first"
	@echo "download; pip is quiet meanwhile)"
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

## Install, render the built-in default scene to render.png (the picture first: it compiles
## only the kernels it needs), then compile every other kernel variant into the per-user cache
## (whitted warm), and say how to use the `whitted` command from here on (it lives in $(VENV)/bin)
demo: install
	$(BIN)/whitted render -o render.png
	@echo "render.png is ready; now compiling the other kernel variants (CSG, caustics, ...) once,"
	@echo "so that no later command waits for them:"
	$(BIN)/whitted warm
	@echo "whitted is installed in $(VENV)/; to use the whitted command in this shell, type:"
	@echo "    . $(VENV)/bin/activate"

## Install the test dependencies, lint, then run the whole test suite
test: install-test
	$(BIN)/ruff check .
	$(BIN)/python -m pytest -q

## The render smoke tests again with the oldest Numba pyproject.toml allows (stock Numba:
## jit/dispatcher.py verifies its tuning on newer ones), in a second virtual environment
## that holds only that Numba, its llvmlite and a NumPy it supports, and takes everything else
## from $(VENV)
OLDEST_NUMBA := $(shell sed -n 's/.*"numba>=\([0-9.]*\),.*/\1/p' pyproject.toml)
OLDEST_VENV ?= .venv-oldest-numba
$(OLDEST_VENV)/.ready: pyproject.toml $(VENV)/.test-deps
	$(PYTHON) -m venv $(OLDEST_VENV)
	$(OLDEST_VENV)/bin/python -m pip install --quiet 'numba==$(OLDEST_NUMBA).*' 'numpy<2.1'
	$(BIN)/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])' \
		> $$($(OLDEST_VENV)/bin/python -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')/whitted-main-venv.pth
	@touch $@

test-oldest-numba: $(OLDEST_VENV)/.ready
	$(OLDEST_VENV)/bin/python -c 'import numba; print("oldest Numba:", numba.__version__)'
	PYTHONPATH=$(CURDIR)/src WHITTED_CACHE_DIR=$(CURDIR)/.cache-oldest-numba \
		$(OLDEST_VENV)/bin/python -m pytest -q \
		-p no:cacheprovider tests/test_kernel_cache.py tests/test_jit.py \
		tests/test_shapes.py -k 'not two_cold'

## What a pip user gets: build the wheel, install it into a fresh virtual environment (only
## the wheel and its core dependencies), then from an empty folder render an example by its
## name, copy the examples out and render one by path, and run the quick benchmark
WHEEL_VENV ?= .venv-wheel
check-wheel: $(VENV)/.test-deps
	rm -rf dist $(WHEEL_VENV)
	$(BIN)/python -m build --wheel --outdir dist .
	$(PYTHON) -m venv $(WHEEL_VENV)
	$(WHEEL_VENV)/bin/python -m pip install --quiet dist/whitted-*.whl
	set -e; here=$$(mktemp -d); cd $$here; \
	  $(abspath $(WHEEL_VENV))/bin/whitted render glass_cube -W 96 -H 72 -o cube.png; \
	  $(abspath $(WHEEL_VENV))/bin/whitted examples ex; \
	  $(abspath $(WHEEL_VENV))/bin/whitted render ex/textured.toml -W 96 -H 72 -o textured.png; \
	  $(abspath $(WHEEL_VENV))/bin/whitted render ex/models/teapot.obj -W 96 -H 72 -o teapot.png; \
	  $(abspath $(WHEEL_VENV))/bin/whitted bench --quick --scene seed000; \
	  ! $(abspath $(WHEEL_VENV))/bin/whitted stefan validate 2> stefan.err; \
	  grep -q 'install whitted\[stefan\]' stefan.err; \
	  cd $(CURDIR); rm -rf $$here
	@echo "check-wheel: the installed wheel renders, copies its examples and runs the bench"

## The tests whose outcome depends on the machine's speed (marker `timing`), run apart
test-timing: install-test
	$(BIN)/python -m pytest -q -m timing

## Line coverage of the whole suite, the commands it runs as subprocesses included, and the
## kernels run as plain Python (tests/test_python_kernels.py runs them with NUMBA_DISABLE_JIT=1)
coverage: install-test
	rm -rf .cache/coverage && mkdir -p .cache/coverage
	$(BIN)/python -m coverage run -m pytest -q -p no:cacheprovider
	$(BIN)/python -m coverage combine -q
	$(BIN)/python -m coverage report --sort=cover
	$(BIN)/python -m coverage report --omit='*/gui/*,*/cli/*,*/program.py,*/__main__.py' \
	  --format=total | sed 's/^/non-interface code (without cli\/, gui\/): /; s/$$/ %/'

## Render the benchmark scenes (benchmarks/) and print the timing table
bench: install
	$(BIN)/whitted bench

lint: install-test
	$(BIN)/ruff check .

clean:
	rm -rf $(VENV) $(OLDEST_VENV) $(WHEEL_VENV) .cache .cache-oldest-numba build dist *.egg-info \
		src/*.egg-info
