# The two commands of the README: `make demo` and `make test`.
# Both create .venv with the interpreter found as python3 and install the package into it.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: demo test bench clean

# Debian packages the build and the tests need:
#   gcc, libc6-dev, binutils: build_fmu.py compiles the FMU's Linux binary (fmu_src/shim); readelf checks its glibc floor
#   libtbb12: the ecos C++ co-simulation host of the FMU tests
#   debootstrap: bare Debian systems without Python, where the tests run the standalone FMUs
#   libxml2-dev libminizip-dev libsundials-dev zlib1g-dev: fmusim (built from ../shared/vendor), an independent FMI host
#   gcc-mingw-w64-x86-64: build_fmu.py cross-compiles the FMU's standalone Windows binary (build_win64.py)
#   wine wine64: tests/test_win64.py runs the win64 binary in Windows hosts (our C host, fmpy, fmusim)
DEBIAN_PACKAGES := gcc libc6-dev binutils libtbb12 debootstrap libxml2-dev libminizip-dev libsundials-dev zlib1g-dev \
                   gcc-mingw-w64-x86-64 wine wine64

$(STAMP): pyproject.toml
	@missing=$$(for p in $(DEBIAN_PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  if command -v apt-get >/dev/null 2>&1 && [ "$$(id -u)" = 0 ]; then \
	    echo "installing Debian packages:" $$missing; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null; \
	  else echo "note: Debian packages missing and not root, so not installed:" $$missing; \
	    echo "      (without gcc building the FMU fails, without gcc-mingw-w64-x86-64 it needs --no-win64;"; \
	    echo "       the tests that need the others are skipped, saying why)"; fi; \
	fi
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[all]"
	touch $(STAMP)

demo: $(STAMP)
	$(PY) examples/demo.py

# the test files run on TEST_WORKERS processes (pytest-xdist), a file's tests on one of them (its module
# fixtures built once). numba's loops are compiled first, once, into its cache, which the tests then load:
# for this CPU and, side by side, for the CPUs build_fmu.py adds to the FMU (an x86-64-v3 one and any
# x86-64: slewing_model/numerics/targets.py)
TEST_WORKERS ?= 2
COMPILE_LOOPS := import build_fmu; build_fmu.compiled_kernel_files()

test: $(STAMP)
	$(PY) -c "$(COMPILE_LOOPS)"
	$(PY) -m pytest -q -n $(TEST_WORKERS) --dist loadfile --durations=15

# speed figures of the README (several minutes: the FMU memory run takes 100 000 steps)
bench: $(STAMP)
	$(PY) benchmarks/bench_rigid.py
	$(PY) benchmarks/bench_superelement.py
	$(PY) benchmarks/bench_flexible.py
	$(PY) benchmarks/bench_operator.py
	$(PY) benchmarks/bench_friction.py
	$(PY) benchmarks/bench_fmu.py
	$(PY) benchmarks/bench_batch.py
	$(PY) benchmarks/bench_realtime.py
	$(PY) benchmarks/bench_flagged.py

clean:
	rm -rf $(VENV) build *.egg-info results
