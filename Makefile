# The two commands of the README: `make demo` and `make test`.
# Both create .venv with the interpreter found as python3 and install the package into it.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: demo test bench clean

$(STAMP): pyproject.toml
	@# Debian packages: libtbb12 for the ecos C++ co-simulation host of the FMU tests
	@if ! ldconfig -p 2>/dev/null | grep -q 'libtbb.so.12 '; then \
	  if command -v apt-get >/dev/null 2>&1 && [ "$$(id -u)" = 0 ]; then \
	    apt-get update -qq && apt-get install -y -qq libtbb12 >/dev/null; \
	  else echo "note: libtbb12 is missing and cannot be installed here (not root): the ecos host test will be skipped"; fi; \
	fi
	@# a C compiler (gcc, libc6-dev): build_fmu.py compiles the FMU's Linux binary (fmu_src/shim)
	@if ! printf 'int main(void){return 0;}\n' | $${CC:-cc} -x c - -o /dev/null 2>/dev/null; then \
	  if command -v apt-get >/dev/null 2>&1 && [ "$$(id -u)" = 0 ]; then \
	    apt-get update -qq && apt-get install -y -qq gcc libc6-dev >/dev/null; \
	  else echo "error: no working C compiler and not root: install gcc and libc6-dev, or building the FMU fails"; fi; \
	fi
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[all]"
	touch $(STAMP)

demo: $(STAMP)
	$(PY) examples/demo.py

test: $(STAMP)
	$(PY) -m pytest -q

# speed figures of the README (several minutes: the FMU memory run takes 100 000 steps)
bench: $(STAMP)
	$(PY) benchmarks/bench_rigid.py
	$(PY) benchmarks/bench_superelement.py
	$(PY) benchmarks/bench_flexible.py
	$(PY) benchmarks/bench_operator.py
	$(PY) benchmarks/bench_friction.py
	$(PY) benchmarks/bench_fmu.py
	$(PY) benchmarks/bench_batch.py

clean:
	rm -rf $(VENV) build *.egg-info results
