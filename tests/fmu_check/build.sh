#!/usr/bin/env bash
# The FMU Compliance Checker (modelica-tools/FMUComplianceChecker, BSD-3), built from local clones: its
# CMake would download FMI Library (modelon-community/fmi-library) 2.0.3; here FMIL's sources are taken from
# a clone instead, so nothing is downloaded. Needs cmake and gcc; about 2 minutes on 2 cores.
#   git clone https://github.com/modelica-tools/FMUComplianceChecker
#   git clone https://github.com/modelon-community/fmi-library
#   bash tests/fmu_check/build.sh FMUComplianceChecker fmi-library [OUT]
# The binary lands in OUT (default $SLEWING_CACHE_DIR/fmucheck/, else ~/.cache/slewing_model/fmucheck/), where tests/test_fmu_check.py finds it
# (or where SLEWING_FMUCHECK names it). The checker tests FMI 1.0 and 2.0 FMUs only.
set -euo pipefail
CHECKER=$(cd "$1" && pwd)
FMIL=$(cd "$2" && pwd)
OUT=${3:-${SLEWING_CACHE_DIR:-$HOME/.cache/slewing_model}/fmucheck}
CHECKER_COMMIT=c704b983b979f57681a5322889360b7688248088   # the checker's last commit (2023-10-16)
FMIL_TAG=2.0.3                                            # the FMIL version the checker's CMakeLists.txt pins
git_dir() { if [ -d "$1/.git" ]; then echo "$1/.git"; else echo "$1"; fi; }   # a clone or a bare mirror
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$WORK/src/FMIL" "$WORK/build" "$OUT"
git --git-dir="$(git_dir "$CHECKER")" archive "$CHECKER_COMMIT" | tar -x -C "$WORK/src"
git --git-dir="$(git_dir "$FMIL")" archive "$FMIL_TAG" | tar -x -C "$WORK/src/FMIL"
cd "$WORK/src"
# no download step: FMIL's sources are in ./FMIL already (CMakeLists.txt has CRLF line ends)
sed -i 's|^\tGIT_REPOSITORY "https://github.com/modelon-community/fmi-library.git"|\tDOWNLOAD_COMMAND ""|; /^\tGIT_TAG 2.0.3\r\?$/d' \
  CMakeLists.txt
cd "$WORK/build"
cmake -DFMUCHK_INSTALL_PREFIX="$WORK/install" "$WORK/src" > cmake.log 2>&1 || { tail -30 cmake.log; exit 1; }
make -j"$(nproc)" install > make.log 2>&1 || { tail -30 make.log; exit 1; }
cp "$WORK/install/fmuCheck.linux64" "$OUT/"
echo "$OUT/fmuCheck.linux64"
