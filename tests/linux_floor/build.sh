#!/usr/bin/env bash
# Builds the floor-lowered Linux runtime of the standalone FMU: a CPython 3.11 and pythonfmu's FMI 2.0
# export library compiled in a Debian 11 (bullseye, glibc 2.31, GCC 10) build chroot, so that the FMU's Linux
# binaries need nothing newer than glibc 2.28 (RHEL 8, Debian 10) and GCC 6's libstdc++ (llvmlite's wheel). As root (debootstrap, chroot), on a Debian machine with
# debootstrap and curl; after `make .venv/.installed` (the numpy, numba, llvmlite versions are the venv's).
#
#   bash tests/linux_floor/build.sh        prints the folder of the result (its last line)
#
# What it makes, each step once (kept; a second run takes seconds):
#   $CHROOTS/bullseye-build      debootstrap --variant=minbase bullseye + build tools (the bare `bullseye` chroot,
#                                the test target, stays bare)
#   $CHROOTS/sources/            CPython 3.11.2's source (Debian's orig tarball of python3.11 3.11.2, which is
#                                python.org's Python-3.11.2.tgz) and the pythonfmu 0.6.9 sdist, pinned by sha256
#   $OUT/cpython-3.11.2-<sha>/   CPython built with --enable-shared and glibc_2_28.h (no symbol newer than glibc 2.28),
#                                the venv's numpy/numba/llvmlite manylinux wheels
#                                installed into it; its bin/python3.11 is what `build_fmu.py --runtime-python` takes
#   $OUT/pythonfmu-export-0.7.0-<sha>/libpythonfmu-export.so
#                                pythonfmu's FMI 2.0 export library: the C++ source of the pythonfmu 0.6.9 sdist
#                                (0.7.0's sdist has none; pythonfmu3's sdist holds the FMI 3.0 one)
#                                with the one change 0.7.0 made to it (setup_experiment gets stop time and tolerance:
#                                pythonfmu-0.6.9-setup-experiment.patch), compiled with g++ 10, its libstdc++ linked
#                                in (hidden): it then needs no GLIBCXX version at all (RHEL 8 has GCC 8's libstdc++)
# CHROOTS is $SLEWING_CHROOT_DIR (default /var/cache/slewing-chroots), OUT is $CHROOTS/linux-floor.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
CHROOTS=${SLEWING_CHROOT_DIR:-/var/cache/slewing-chroots}
BUILD=$CHROOTS/bullseye-build
OUT=$CHROOTS/linux-floor
SOURCES=$CHROOTS/sources
JOBS=${SLEWING_BUILD_JOBS:-2}
VENV_PY=${VENV_PY:-$root/.venv/bin/python}

CPYTHON_URL=http://deb.debian.org/debian/pool/main/p/python3.11/python3.11_3.11.2.orig.tar.gz
CPYTHON_SHA256=2411c74bda5bbcfcddaf4531f66d1adc73f247f529aee981b029513aefdbf849
CPYTHON_VERSION=3.11.2
PYTHONFMU_SDIST=pythonfmu-0.6.9.tar.gz
PYTHONFMU_SHA256=13eab981d3c86704ab19b35ebcee9347b2dcc378bbe8d0b43c9ae1fe35bc9fa7
BUILD_PACKAGES="build-essential pkg-config ca-certificates libffi-dev zlib1g-dev libbz2-dev liblzma-dev libssl-dev"
BUILD_PACKAGES="$BUILD_PACKAGES uuid-dev libxml2-dev libminizip-dev libicu-dev"  # the last three: fmusim

log() { echo "[linux-floor $(date +%H:%M:%S)] $*" >&2; }
in_build() { chroot "$BUILD" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root DEBIAN_FRONTEND=noninteractive "$@"; }
[ "$(id -u)" = 0 ] || { echo "needs root (debootstrap, chroot)" >&2; exit 2; }
mkdir -p "$OUT" "$SOURCES"

# ---- the build chroot: Debian 11 with the tools ---------------------------------------------------------------
if [ ! -f "$BUILD/.slewing-build-tools" ]; then
  t0=$SECONDS
  rm -rf "$BUILD.partial"
  if [ -d "$CHROOTS/bullseye/usr/bin" ]; then
    cp -a "$CHROOTS/bullseye" "$BUILD.partial"            # the bare system as made by debootstrap, copied
    find "$BUILD.partial/tmp" -mindepth 1 -delete          # without what the tests left in its /tmp
  else
    debootstrap --variant=minbase bullseye "$BUILD.partial" >&2
  fi
  cp /etc/resolv.conf "$BUILD.partial/etc/resolv.conf"
  chroot "$BUILD.partial" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root DEBIAN_FRONTEND=noninteractive \
    sh -c "apt-get update -qq && apt-get install -y -qq --no-install-recommends $BUILD_PACKAGES >/dev/null && apt-get clean"
  echo "$BUILD_PACKAGES" > "$BUILD.partial/.slewing-build-tools"
  rm -rf "$BUILD"; mv "$BUILD.partial" "$BUILD"
  log "build chroot made in $((SECONDS - t0)) s"
fi

fetch() {  # fetch URL FILE SHA256
  if [ ! -f "$SOURCES/$2" ] || ! echo "$3  $SOURCES/$2" | sha256sum -c --quiet - 2>/dev/null; then
    curl -fsSL -o "$SOURCES/$2.partial" "$1"
    echo "$3  $SOURCES/$2.partial" | sha256sum -c --quiet - || { echo "sha256 of $1 differs from the pinned one" >&2; exit 1; }
    mv "$SOURCES/$2.partial" "$SOURCES/$2"
  fi
}

# ---- CPython ----------------------------------------------------------------------------------------------------
versions=$("$VENV_PY" -c "from importlib.metadata import version as v; print(' '.join(f'{n}=={v(n)}' for n in ('numpy', 'numba', 'llvmlite')))")
key=$(cat "$here/glibc_2_28.h" <(echo "$CPYTHON_SHA256 $versions layout-2") | sha256sum | cut -c1-12)
PY_OUT=$OUT/cpython-$CPYTHON_VERSION-$key
if [ ! -x "$PY_OUT/bin/python3.11" ]; then
  t0=$SECONDS
  fetch "$CPYTHON_URL" "python3.11_$CPYTHON_VERSION.orig.tar.gz" "$CPYTHON_SHA256"
  prefix=/opt/slewing-floor/cpython-$CPYTHON_VERSION-$key
  rm -rf "$BUILD/tmp/cpython" "$BUILD$prefix"
  mkdir -p "$BUILD/tmp/cpython"
  tar xzf "$SOURCES/python3.11_$CPYTHON_VERSION.orig.tar.gz" -C "$BUILD/tmp/cpython" --strip-components=1
  cp "$here/glibc_2_28.h" "$BUILD/tmp/glibc_2_28.h"
  log "building CPython $CPYTHON_VERSION in Debian 11 (make -j$JOBS; a few minutes) ..."
  in_build sh -c "cd /tmp/cpython && ./configure -q --prefix=$prefix --enable-shared --with-ensurepip=install \
      CFLAGS='-include /tmp/glibc_2_28.h' ac_cv_func_sem_clockwait=no LDFLAGS=-Wl,-rpath,$prefix/lib >/tmp/cpython-configure.log 2>&1 && nice -n 10 make -s -j$JOBS >/tmp/cpython-make.log 2>&1 \
      && make -s install >/tmp/cpython-install.log 2>&1" \
    || { tail -30 "$BUILD"/tmp/cpython-*.log >&2; exit 1; }
  log "CPython built in $((SECONDS - t0)) s"
  # the wheels of the venv's versions, manylinux for glibc 2.28 at most (pip downloads them here; no network in the chroot)
  rm -rf "$BUILD/tmp/wheels"; mkdir -p "$BUILD/tmp/wheels"
  "$VENV_PY" -m pip download -q --no-deps --only-binary=:all: --python-version 3.11 --implementation cp --abi cp311 \
      --platform manylinux_2_28_x86_64 --platform manylinux_2_27_x86_64 --platform manylinux_2_17_x86_64 \
      --platform manylinux2014_x86_64 -d "$BUILD/tmp/wheels" $versions
  in_build "$prefix/bin/python3.11" -m pip install -q --no-index --find-links /tmp/wheels --no-warn-script-location $versions
  rm -rf "$PY_OUT.partial"
  cp -a "$BUILD$prefix" "$PY_OUT.partial"
  # the interpreter finds its libpython relative to itself, wherever the folder is (here, or inside the chroot)
  "$VENV_PY" -c "import sys; sys.path.insert(0, '$root'); import fmu_build.runtime as b; b.set_runpath('$PY_OUT.partial/bin/python3.11', '\$ORIGIN/../lib')"
  rm -rf "$PY_OUT"; mv "$PY_OUT.partial" "$PY_OUT"
  rm -rf "$BUILD/tmp/cpython" "$BUILD/tmp/wheels"
  log "CPython with $versions: $PY_OUT ($((SECONDS - t0)) s)"
fi

# ---- the libraries beyond glibc that CPython's modules and the wheels need, Debian 11's, beside libpython --------
# (fmu_build/runtime.py takes them from there for an interpreter other than the running one, not from this machine)
if [ ! -f "$PY_OUT/lib/.slewing-libraries" ]; then
  prefix=/opt/slewing-floor/cpython-$CPYTHON_VERSION-$key
  [ -x "$BUILD$prefix/bin/python3.11" ] || { rm -rf "$BUILD$prefix"; mkdir -p "$(dirname "$BUILD$prefix")"; cp -a "$PY_OUT" "$BUILD$prefix"; }
  in_build sh -c "find $prefix -name '*.so*' -type f | xargs ldd 2>/dev/null | sed -n 's#^[[:space:]]*\([^ ]*\) => \(/[^ ]*\) .*#\2 \1#p' | sort -u" \
    | grep -vE '/(libc|libm|libdl|libpthread|librt|libutil|libresolv|libcrypt|ld-linux[-a-z0-9_]*|libstdc\+\+|libgcc_s)\.so' \
    | grep -v "^$prefix/" > "$PY_OUT/lib/.slewing-libraries.partial" || true
  while read -r library name; do           # under the name the modules need (libgomp.so.1, not libgomp.so.1.0.0)
    cp -L "$BUILD$library" "$PY_OUT/lib/$name"
  done < "$PY_OUT/lib/.slewing-libraries.partial"
  mv "$PY_OUT/lib/.slewing-libraries.partial" "$PY_OUT/lib/.slewing-libraries"
  log "Debian 11 libraries beside libpython: $(cut -d' ' -f2 "$PY_OUT/lib/.slewing-libraries" | tr '\n' ' ')"
fi

# ---- pythonfmu's FMI 2.0 export library ------------------------------------------------------------------------
patch_file=$here/pythonfmu-0.6.9-setup-experiment.patch
ekey=$(cat "$patch_file" <(echo "$PYTHONFMU_SHA256 $key") | sha256sum | cut -c1-12)
EXPORT_OUT=$OUT/pythonfmu-export-0.7.0-$ekey
if [ ! -f "$EXPORT_OUT/libpythonfmu-export.so" ]; then
  t0=$SECONDS
  if [ ! -f "$SOURCES/$PYTHONFMU_SDIST" ]; then
    "$VENV_PY" -m pip download -q --no-deps --no-binary :all: pythonfmu==0.6.9 -d "$SOURCES"
  fi
  echo "$PYTHONFMU_SHA256  $SOURCES/$PYTHONFMU_SDIST" | sha256sum -c --quiet -
  rm -rf "$BUILD/tmp/pythonfmu"; mkdir -p "$BUILD/tmp/pythonfmu"
  tar xzf "$SOURCES/$PYTHONFMU_SDIST" -C "$BUILD/tmp/pythonfmu" --strip-components=1
  src=$BUILD/tmp/pythonfmu/pythonfmu/pythonfmu-export
  patch -s -d "$src" -p0 < "$patch_file"
  prefix=/opt/slewing-floor/cpython-$CPYTHON_VERSION-$key
  [ -x "$BUILD$prefix/bin/python3.11" ] || { rm -rf "$BUILD$prefix"; mkdir -p "$(dirname "$BUILD$prefix")"; cp -a "$PY_OUT" "$BUILD$prefix"; }
  log "building pythonfmu's export library in Debian 11 (g++ 10) ..."
  # the two sources its CMakeLists.txt compiles, as its Release build does; compiled directly: Debian 11's cmake 3.18
  # does not find the Development.Module of a Python outside /usr (and no libpython is linked: the host's is used)
  in_build sh -c "cd /tmp/pythonfmu/pythonfmu/pythonfmu-export/src && g++ -std=c++17 -O3 -DNDEBUG -fPIC -shared -I. \
      -I$prefix/include/python3.11 -o /tmp/pythonfmu/libpythonfmu-export.so pythonfmu/fmi2.cpp pythonfmu/PySlaveInstance.cpp \
      -static-libstdc++ -static-libgcc -Wl,--exclude-libs,ALL -lpthread" >&2
  # the same FMI 2.0 functions as the library pythonfmu 0.7.0 ships (in the venv)
  shipped=$("$VENV_PY" -c "import pythonfmu, pathlib; print(pathlib.Path(pythonfmu.__file__).parent / 'resources/binaries/linux64/libpythonfmu-export.so')")
  diff <(nm -D --defined-only "$shipped" | awk '{print $3}' | grep '^fmi2' | sort) \
       <(nm -D --defined-only "$BUILD/tmp/pythonfmu/libpythonfmu-export.so" | awk '{print $3}' | grep '^fmi2' | sort) >&2 \
    || { echo "the rebuilt export library's fmi2 functions differ from pythonfmu's ($shipped)" >&2; exit 1; }
  rm -rf "$EXPORT_OUT.partial"; mkdir -p "$EXPORT_OUT.partial"
  cp "$BUILD/tmp/pythonfmu/libpythonfmu-export.so" "$EXPORT_OUT.partial/"
  strip --strip-unneeded "$EXPORT_OUT.partial/libpythonfmu-export.so"
  rm -rf "$EXPORT_OUT"; mv "$EXPORT_OUT.partial" "$EXPORT_OUT"
  rm -rf "$BUILD/tmp/pythonfmu"
  log "export library: $EXPORT_OUT ($((SECONDS - t0)) s)"
fi

# ---- fmusim for Debian 11 (the chroot tests' independent host) ------------------------------------------------
FMUSIM=$OUT/fmusim-0.0.39-bullseye
vendor=$root/../shared/vendor/fmusim-v0.0.39
if [ ! -x "$FMUSIM" ] && [ -f "$vendor/build.sh" ]; then
  rm -rf "$BUILD/tmp/fmusim-src"; cp -a "$vendor" "$BUILD/tmp/fmusim-src"
  # the vendor's script on a copy whose CVode solver is a stub (fmicvode_stub.c: fmusim 0.0.39 needs sundials 6,
  # Debian 11 has 5; co-simulation does not use the solver), linked without sundials
  cp "$here/fmicvode_stub.c" "$BUILD/tmp/fmusim-src/fmusim/FMICVode.c"
  sed -i 's/ -lsundials_[a-z]*//g' "$BUILD/tmp/fmusim-src/build.sh"
  in_build bash /tmp/fmusim-src/build.sh /tmp/fmusim --static 2>/dev/null
  mv "$BUILD/tmp/fmusim" "$FMUSIM"; rm -rf "$BUILD/tmp/fmusim-src"
  log "fmusim built in Debian 11: $FMUSIM"
fi

rm -rf "$BUILD/opt/slewing-floor"                     # the interpreter's copy in the chroot (kept in $OUT)
ln -sfn "$(basename "$PY_OUT")" "$OUT/python"
ln -sfn "$(basename "$EXPORT_OUT")" "$OUT/pythonfmu-export"
echo "$OUT"
