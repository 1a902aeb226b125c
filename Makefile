# The two commands of the README: `make demo` and `make test`.
# Both create .venv with the interpreter found as python3 and install the package into it.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: demo test docs screenshots bench clean

# Debian packages, each target its own (installed with apt-get when run as root, else named):
#   the demo builds an FMU: gcc, libc6-dev, binutils compile its Linux binary (fmu_src/shim; readelf checks
#   its glibc floor), gcc-mingw-w64-x86-64 cross-compiles its standalone Windows binary (fmu_build/win64.py),
#   wine wine64 and g++-mingw-w64-x86-64 compile its Windows loops ahead of time (numba's pycc under wine,
#   linked with mingw-w64's gcc and g++)
#   the tests also use: libtbb12 (the ecos C++ co-simulation host), debootstrap (bare Debian systems without
#   Python, where the standalone FMUs run), libxml2-dev libminizip-dev libsundials-dev zlib1g-dev (fmusim, built
#   from ../shared/vendor: an independent FMI host), calculix-ccx (the CalculiX reference tests)
DEMO_PACKAGES := gcc libc6-dev binutils gcc-mingw-w64-x86-64 g++-mingw-w64-x86-64 wine wine64
TEST_PACKAGES := $(DEMO_PACKAGES) libtbb12 debootstrap libxml2-dev libminizip-dev libsundials-dev zlib1g-dev \
                 calculix-ccx
define debian_packages
	@missing=$$(for p in $(1); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  if command -v apt-get >/dev/null 2>&1 && [ "$$(id -u)" = 0 ]; then \
	    echo "installing Debian packages:" $$missing; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null; \
	  else echo "note: Debian packages missing and not root, so not installed:" $$missing; \
	    echo "      (without gcc building the FMU fails, without gcc-mingw-w64-x86-64 it needs --no-win64;"; \
	    echo "       the tests that need the others are skipped, saying why)"; fi; \
	fi
endef

# ROSCO, NREL's reference wind turbine controller (slewing_turbine: the turbine loop), for its compiled library
# libdiscon.so only: installed without its dependencies, which pull WISDEM and 1.4 GB that the loop never
# imports; ROSCO needs Python 3.11 or newer (with 3.10 the turbine loop and its tests are left out, saying so)
ROSCO := rosco==2.10.6
define rosco
	@if $(PY) -c 'import sys; sys.exit(sys.version_info < (3, 11))'; then \
	  $(PY) -m pip install --quiet --no-deps $(ROSCO); \
	else echo "note: $(ROSCO) needs Python 3.11 or newer: the turbine loop is left out"; fi
endef

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[all]"
	$(call rosco)
	touch $(STAMP)

demo: $(STAMP)
	$(call debian_packages,$(DEMO_PACKAGES))
	$(PY) examples/demo.py

# the test files run on TEST_WORKERS processes (pytest-xdist), a file's tests on one of them (its module
# fixtures built once). The loops are compiled first, once, into their caches, which the tests then load:
# numba's for this CPU and the FMU's modules compiled ahead of time (fmu_build/aot.py, the tests take them
# from the user's cache). The --numba FMU's tests, which compile numba's loops for two more CPUs, are opt-in
# (SLEWING_TEST_NUMBA_FMU=1). numba's loops compile on one core (about 3 minutes) beside the FMU's two modules
# on two (1.5 minutes each): 3 minutes of wall time on 2 cores instead of 4. Beside them, as root,
# tests/platform_builds.py makes what the win64 and Debian 11 floor tests need where it is missing (the floor
# runtime, mingw's fmusim, the win64 half's loops: 8-14 minutes once, much of it downloads and debootstrap,
# kept in /var/cache and the aot cache; seconds after)
TEST_WORKERS ?= 2
COMPILE_LOOPS := from slewing_model.friction import kernel; kernel.compile_all()
COMPILE_LOOPS_AOT := import fmu_build.aot; fmu_build.aot.prepare_cache()

test: $(STAMP)
	$(call debian_packages,$(TEST_PACKAGES))
	$(PY) tests/platform_builds.py & platforms=$$!; $(PY) -c "$(COMPILE_LOOPS)" & numba=$$!; \
	  $(PY) -c "$(COMPILE_LOOPS_AOT)"; aot=$$?; wait $$numba; numba=$$?; wait $$platforms; platforms=$$?; \
	  [ $$aot = 0 ] && [ $$numba = 0 ] && [ $$platforms = 0 ]
	$(PY) -m pytest -q -n $(TEST_WORKERS) --dist loadfile --durations=15

# the benchmark suite's main set (python -m benchmarks --list names them all; tables printed and written as
# JSON to results/bench/); the FMU benchmarks measure the released version named by --baseline beside this one
bench: $(STAMP)
	$(PY) -m benchmarks main

# the documentation site (Sphinx, warnings as errors) into docs/_build/html; its tools pinned in the docs extra
DOCS_STAMP := $(VENV)/.docs-installed
$(DOCS_STAMP): $(STAMP)
	$(PY) -m pip install --quiet -e ".[docs]"
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	rm -rf docs/_build
	$(PY) -m sphinx -W --keep-going -q -b html docs docs/_build/html
	@echo "the site: docs/_build/html/index.html"

# screenshots of the built site with headless Chromium (Debian's chromium), to look at it as a reader does
SHOTS := index guide/bearing-files validation/calculix-bolted
screenshots: docs
	@command -v chromium >/dev/null 2>&1 || { [ "$$(id -u)" = 0 ] && apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null; }
	mkdir -p results/screenshots
	for page in $(SHOTS); do \
	  chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --virtual-time-budget=5000 --window-size=1400,1800 \
	    --screenshot=results/screenshots/$$(echo $$page | tr / -).png "file://$(CURDIR)/docs/_build/html/$$page.html" 2>/dev/null; \
	done
	@ls results/screenshots

clean:
	rm -rf $(VENV) build *.egg-info results docs/_build
