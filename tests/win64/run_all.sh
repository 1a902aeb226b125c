#!/usr/bin/env bash
# The win64 tests in full (tests/test_win64.py): 5 runs per FMU and host, fmusim for mingw built first (about
# 5 minutes the first time, kept in /var/cache/slewing-wine), and the loops of --win64-numba compiled under
# wine (about 5 minutes the first time per version of the loops, kept in /var/cache/slewing-wine/build), and
# the default build's loops compiled ahead of time for win64 (fmu_build/win64.py's aot_module: about 2.5 minutes
# the first time per version of the loops, kept beside the Linux modules in the aot cache). As root, after
# `make .venv/.installed`; about 10 minutes on 2 cores with all built.
#   bash tests/win64/run_all.sh [pytest options]
set -euo pipefail
cd "$(dirname "$0")/../.."
SLEWING_TEST_PLATFORMS_FULL=1 SLEWING_TEST_NUMBA_FMU=1 SLEWING_WINE_RUNS=${SLEWING_WINE_RUNS:-5} SLEWING_BUILD_FMUSIM=1 SLEWING_BUILD_WIN64_NUMBA=1 SLEWING_BUILD_WIN64_AOT=1 nice -n 10 .venv/bin/python -m pytest -q tests/test_win64.py "$@"
