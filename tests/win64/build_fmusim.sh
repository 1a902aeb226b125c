#!/usr/bin/env bash
# Cross-compiles fmusim v0.0.39 (../shared/vendor, BSD-2-Clause) for Windows with mingw-w64, for tests/test_win64.py.
#
#   tests/win64/build_fmusim.sh OUTPUT.exe
#
# Debian packages only zlib for mingw (libz-mingw-w64-dev). fmusim's other libraries are built here for mingw
# from Debian's own source packages (`apt-get source`; a deb-src entry for bookworm is added when there is none):
#   libxml2 2.9.14 (static, no iconv/icu/lzma/zlib/http/ftp), sundials 6.4.1 (CVODE only, static), minizip 1.1
#   (ioapi, iowin32, unzip). The sources and the built libraries are kept in $SLEWING_WINE_DIR
#   (default /var/cache/slewing-wine): about 5 minutes on 2 cores the first time, a few seconds after.
# Needs root (apt-get), cmake, gcc-mingw-w64-x86-64, libz-mingw-w64-dev, dpkg-dev.
set -euo pipefail
out=$(realpath -m "${1:?usage: build_fmusim.sh OUTPUT.exe}")
here=$(cd "$(dirname "$0")" && pwd)
vendor=${SLEWING_FMUSIM_SOURCE:-$here/../../../shared/vendor/fmusim-v0.0.39}
vendor=$(cd "$vendor" && pwd)
top=${SLEWING_WINE_DIR:-/var/cache/slewing-wine}
src=$top/src
prefix=$top/mingw
cc=x86_64-w64-mingw32-gcc
mkdir -p "$src" "$prefix"
jobs=${SLEWING_JOBS:-2}
toolchain=(-DCMAKE_SYSTEM_NAME=Windows -DCMAKE_C_COMPILER=$cc -DCMAKE_RC_COMPILER=x86_64-w64-mingw32-windres
           -DCMAKE_FIND_ROOT_PATH=/usr/x86_64-w64-mingw32 -DCMAKE_INSTALL_PREFIX=$prefix -DCMAKE_BUILD_TYPE=Release
           -DBUILD_SHARED_LIBS=OFF)

need=()
for p in gcc-mingw-w64-x86-64 libz-mingw-w64-dev cmake dpkg-dev; do
  dpkg-query -W -f='${Status}' $p 2>/dev/null | grep -q 'ok installed' || need+=($p)
done
if ((${#need[@]})); then DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${need[@]}" >/dev/null; fi

# Debian's sources
if ! ls "$src"/libxml2-*/CMakeLists.txt "$src"/sundials-*/CMakeLists.txt "$src"/minizip-*/unzip.c >/dev/null 2>&1; then
  if ! grep -rqs '^Types: deb-src\|^deb-src' /etc/apt/sources.list /etc/apt/sources.list.d/; then
    cat > /etc/apt/sources.list.d/slewing-deb-src.sources <<'EOF'
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
    apt-get update -qq
  fi
  (cd "$src" && apt-get source -qq libxml2 sundials minizip >/dev/null 2>&1)
fi
libxml2=$(ls -d "$src"/libxml2-*/ | head -1)
sundials=$(ls -d "$src"/sundials-*/ | head -1)
minizip=$(ls -d "$src"/minizip-*/ | head -1)

if [[ ! -f $prefix/lib/libxml2.a ]]; then
  rm -rf "$top/build-libxml2" && mkdir -p "$top/build-libxml2"
  cmake -S "$libxml2" -B "$top/build-libxml2" "${toolchain[@]}" -DLIBXML2_WITH_ICONV=OFF -DLIBXML2_WITH_ICU=OFF \
    -DLIBXML2_WITH_LZMA=OFF -DLIBXML2_WITH_ZLIB=OFF -DLIBXML2_WITH_PYTHON=OFF -DLIBXML2_WITH_HTTP=OFF \
    -DLIBXML2_WITH_FTP=OFF -DLIBXML2_WITH_TESTS=OFF -DLIBXML2_WITH_PROGRAMS=OFF -DLIBXML2_WITH_MODULES=OFF >/dev/null
  nice cmake --build "$top/build-libxml2" -j "$jobs" >/dev/null
  cmake --install "$top/build-libxml2" >/dev/null
fi
if [[ ! -f $prefix/lib/libsundials_cvode.a ]]; then
  rm -rf "$top/build-sundials" && mkdir -p "$top/build-sundials"
  cmake -S "$sundials" -B "$top/build-sundials" "${toolchain[@]}" -DBUILD_STATIC_LIBS=ON -DBUILD_ARKODE=OFF \
    -DBUILD_CVODES=OFF -DBUILD_IDA=OFF -DBUILD_IDAS=OFF -DBUILD_KINSOL=OFF -DBUILD_CVODE=ON -DEXAMPLES_ENABLE_C=OFF \
    -DEXAMPLES_INSTALL=OFF -DBUILD_FORTRAN_MODULE_INTERFACE=OFF -DSUNDIALS_ENABLE_ERROR_CHECKS=OFF >/dev/null
  nice cmake --build "$top/build-sundials" -j "$jobs" >/dev/null
  cmake --install "$top/build-sundials" >/dev/null
fi
if [[ ! -f $prefix/lib/libminizip.a ]]; then
  mkdir -p "$top/build-minizip" "$prefix/include/minizip"
  for f in ioapi unzip iowin32; do
    $cc -O2 -c -o "$top/build-minizip/$f.o" "$minizip/$f.c"
  done
  x86_64-w64-mingw32-ar rcs "$prefix/lib/libminizip.a" "$top/build-minizip"/*.o
  cp "$minizip"/{ioapi.h,unzip.h,iowin32.h,crypt.h} "$prefix/include/minizip/"
fi

# fmusim: its sources name Windows headers with capitals (Windows.h, Shlwapi.h); mingw's are lower case
caps=$top/build-fmusim/caps
mkdir -p "$caps"
ln -sf /usr/share/mingw-w64/include/windows.h "$caps/Windows.h"
ln -sf /usr/share/mingw-w64/include/shlwapi.h "$caps/Shlwapi.h"
cd "$vendor/fmusim"
sources=(../src/FMI.c ../src/FMI1.c ../src/FMI2.c ../src/FMI3.c csv.c FMIUtil.c FMIEuler.c FMICVode.c FMIModelDescription.c
         FMIBuildDescription.c FMIRecorder.c FMIZip.c FMISimulation.c FMIStaticInput.c FMI1CSSimulation.c FMI1MESimulation.c
         FMI2CSSimulation.c FMI2MESimulation.c FMI3CSSimulation.c FMI3MESimulation.c fmusim.c miniunzip.c
         ../src/structured_variable_name.yy.c ../src/structured_variable_name.tab.c)
nice $cc -O1 -g0 -s -w -DSTRSAFE_NO_DEPRECATE '-DFMUSIM_VERSION="0.0.39"' -DSUN_COMM_NULL=NULL -DLIBXML_STATIC -I. -I../include -I"$caps" \
  -I"$prefix/include" -I"$prefix/include/libxml2" -I"$prefix/include/minizip" -o "$out" "${sources[@]}" \
  -L"$prefix/lib" -lminizip -lxml2 -lsundials_cvode -lsundials_nvecserial -lsundials_sunmatrixdense \
  -lsundials_sunlinsoldense -lz -lshlwapi -lws2_32 -lbcrypt -lpthread -static
echo "built $out"
