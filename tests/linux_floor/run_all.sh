#!/usr/bin/env bash
# The floor-lowered Linux FMU in full (tests/test_linux_floor.py): builds CPython 3.11, pythonfmu's FMI 2.0 export
# library and fmusim in a Debian 11 build chroot (tests/linux_floor/build.sh: about 4 minutes on 2 cores the first
# time, kept in /var/cache/slewing-chroots/linux-floor; seconds after), then runs the floor-lowered FMUs in the bare
# Debian 11 chroot: 20 fmusim runs per FMI version and our C host, against fmpy here. As root, after
# `make .venv/.installed`.
#   bash tests/linux_floor/run_all.sh [pytest options]
set -euo pipefail
cd "$(dirname "$0")/../.."
nice -n 10 bash tests/linux_floor/build.sh
SLEWING_TEST_NUMBA_FMU=1 SLEWING_FLOOR_FMUSIM_RUNS=${SLEWING_FLOOR_FMUSIM_RUNS:-20} nice -n 10 .venv/bin/python -m pytest -q tests/test_linux_floor.py "$@"
