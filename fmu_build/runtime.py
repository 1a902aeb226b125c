"""The Python runtime a standalone FMU carries (build time only; used by ``build_fmu.py``).

A standalone FMU runs its model on a machine that has no Python: it carries the building
interpreter's (or another one's: ``build_fmu.py --runtime-python``, ``--linux-floor``) shared library, the part of the standard library a numpy model uses, numpy and,
as the user chooses, numba with llvmlite. The tree is laid out as a Python prefix,

    binaries/<platform>/python/lib/libpython3.X.so.1.0
                               lib/python3.X/...                the standard library
                               lib/python3.X/lib-dynload/...    its extension modules
                               lib/python3.X/site-packages/...  numpy [, numba, llvmlite]
                               lib/libffi.so.8 ...              the libraries they need beyond glibc

so that the FMU's Linux layer (``fmu_src/shim/python_runtime.c``) starts it with its home set to
that folder, found relative to the layer's own binary: no absolute path, and nothing of the
target machine's Python (``PYTHONPATH``, user site-packages) is looked at.

What is done to the copied files, so that nothing inside names the building machine:

* the run-time search paths (``RUNPATH``) of libpython and the extension modules, which name
  the building prefix, are rewritten in place to ``$ORIGIN``-relative ones;
* any other occurrence of a building machine's path (compiled-in prefixes of libpython, the
  ``_sysconfigdata`` module, numba's cache) is overwritten with ``/`` characters of the same
  length: the bytes keep their length, so ELF tables and pickles stay valid, and the strings
  now name ``/`` (they are fallbacks and error-message texts, never used to find a file);
* the glibc and libstdc++ versions every ELF file needs are read from its ``.gnu.version_r``,
  so that the FMU can state its floor (``glibc=`` in ``resources/python_runtime.txt``) and the
  layer can refuse an older system with a message instead of a loader error;
* every module's bytecode is compiled beside its source (:mod:`fmu_build.bytecode`: hash-based files
  that a freshly unpacked FMU reads instead of compiling its runtime at its first instantiation).

The staged tree is cached (``$SLEWING_CACHE_DIR/fmu_runtime``) per interpreter, package
versions and platform folder, as a zip whose entries are appended to each FMU.
"""
from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from fmu_build.bytecode import compile_tree

#: the folder of the runtime inside ``binaries/<platform>/``
RUNTIME_FOLDER = "python"
#: version of this file's layout: part of the cache key
LAYOUT = 5

#: standard-library folders and modules a numpy model never imports (tests, GUIs, installers, build files)
STDLIB_EXCLUDED = {"test", "tkinter", "idlelib", "turtledemo", "ensurepip", "lib2to3", "pydoc_data",
                   "site-packages", "__pycache__", "venv", "turtle.py"}
STDLIB_EXCLUDED_PREFIXES = ("config-",)
#: extension modules left out: tests, terminals, GUIs, network security (libssl is no part of a bare system)
DYNLOAD_EXCLUDED = re.compile(r"^(_test|_xx|xxlimited|_ctypes_test|_tkinter|_curses|readline|nis|_ssl|_hashlib|"
                              r"_sqlite3|_crypt|ossaudiodev|spwd|audioop|_dbm|_gdbm)")
#: files left out of the packages: tests, type stubs, C headers and sources
PACKAGE_EXCLUDED = re.compile(r"(^|/)(tests?|__pycache__|include|_pyinstaller)(/|$)|\.(pyi|pxd|h|c|cpp)$")

# ---- what the runtime without numba keeps: the import audit --------------------------------------
# ``python -m fmu_build.import_audit`` runs the FMUs built on this runtime (bearing FMI 2.0 and 3.0 with the loops
# compiled ahead of time, drive, time table) with the runtime untrimmed in C hosts under strace, through their
# paths (steps, the state got, set and serialized, refused steps, unloads and reloads, the life accumulators,
# the rotating frame, bounded steps, rigid rings, a bad parameter's error), and records every file of the runtime
# they open. What it found (CPython 3.11.7, numpy 2.4.6) is in the *_IMPORTED sets; the runtime keeps those, whole
# packages where a package is imported, and a margin (*_MARGIN, with its reasons), and leaves the rest out
# (the pitch bearing FMU's Linux half: 16.8 MB zipped, 56 MB unpacked; 21.1 MB and 70 MB untrimmed). The runtime with numba
# (``--numba``) keeps the standard library and numpy whole but for the exclusions above: numba's JIT imports much
# of both. After a change of Python, numpy or the FMUs' imports, run the audit again: it fails, naming the files,
# where a run opens one that these lists leave out.
#: the standard library's top-level modules and packages the runs import (the audit)
STDLIB_IMPORTED = frozenset({
    "__future__", "_compat_pickle", "_compression", "_weakrefset", "argparse", "ast", "bisect", "bz2", "collections",
    "contextlib", "contextvars", "copy", "copyreg", "csv", "ctypes", "dataclasses", "datetime", "dis", "encodings",
    "enum", "fnmatch", "functools", "gettext", "hashlib", "importlib", "inspect", "ipaddress", "json", "keyword",
    "linecache", "logging", "lzma", "numbers", "opcode", "operator", "pathlib", "pickle", "platform", "random", "re",
    "reprlib", "shutil", "string", "struct", "tempfile", "textwrap", "threading", "token", "tokenize", "tomllib",
    "traceback", "types", "typing", "urllib", "uuid", "warnings", "weakref", "xml", "zipfile"})
#: ... and kept besides (the margin): the modules CPython 3.11 has frozen into libpython (read from files where
#: an interpreter runs with ``-X frozen_modules=off``), sysconfig and its data, locale (gettext's path when a
#: message is translated), and modules the imported ones import lazily (datetime's strptime, decimal, heapq, pprint)
STDLIB_MARGIN = frozenset({
    "abc", "codecs", "io", "os", "site", "stat", "posixpath", "genericpath", "ntpath", "_collections_abc",
    "_sitebuiltins", "zipimport", "runpy", "sysconfig", "locale", "_strptime", "calendar", "decimal", "_pydecimal",
    "fractions", "heapq", "pprint", "_threading_local", "signal", "selectors", "subprocess"})
#: the extension modules of lib-dynload the runs load (the audit)
DYNLOAD_IMPORTED = frozenset({
    "_bisect", "_blake2", "_bz2", "_contextvars", "_csv", "_ctypes", "_datetime", "_elementtree", "_json", "_lzma",
    "_md5", "_opcode", "_pickle", "_random", "_sha1", "_sha256", "_sha3", "_sha512", "_struct", "_typing", "_uuid",
    "binascii", "math", "pyexpat", "zlib"})
#: ... and kept besides (the margin): those of the margin's modules
DYNLOAD_MARGIN = frozenset({"_heapq", "_decimal", "array", "fcntl", "select", "_posixsubprocess"})
#: numpy's subpackages the runs import (the audit), kept whole; numpy's top-level modules are all kept. Not
#: imported, so left out: random, ma, polynomial, testing, f2py, distutils, typing, doc, _pyinstaller
#: (numpy 2 imports its subpackages when first named; the FMU names none of those)
NUMPY_IMPORTED = frozenset({"_core", "_typing", "_utils", "fft", "lib", "linalg", "matrixlib"})
#: ... and kept besides (the margin): numpy 1's module names that numpy 2 answers (numpy.core, for pickles
#: of numpy 1), and its small namespaces
NUMPY_MARGIN = frozenset({"core", "ctypeslib", "char", "rec", "strings"})
#: numpy's extension modules for its own tests (``numpy._core._multiarray_tests`` ...), never imported by the runs
NUMPY_TEST_MODULES = re.compile(r"^_core/_(multiarray_tests|umath_tests|rational_tests|struct_ufunc_tests|"
                                r"operand_flag_tests|simd)\.")


def _module_name(name: str) -> str:
    """The module a file of a folder names: ``json`` for ``json``, ``json.py`` and
    ``__pycache__/json.cpython-311.pyc`` (written by a run)."""
    return name.split(".")[0]


def kept(relative: str, minor: str) -> bool:
    """Whether the runtime without numba (trimmed) keeps the file ``relative`` (a path below the runtime's
    prefix, ``lib/python3.11/json/decoder.py``) of the untrimmed one: by the lists above."""
    stdlib = f"lib/python{minor}/"
    if not relative.startswith(stdlib):
        return True                                         # libpython and the libraries beside it
    parts = relative[len(stdlib):].split("/")
    if parts[0] == "lib-dynload":
        return _module_name(parts[-1]) in DYNLOAD_IMPORTED | DYNLOAD_MARGIN
    if parts[:2] == ["site-packages", "numpy"]:
        inside = parts[2:]
        if len(inside) == 1 or inside[0] == "__pycache__":
            return True                                     # numpy's own modules (__init__, _globals ...)
        return inside[0] in NUMPY_IMPORTED | NUMPY_MARGIN and not NUMPY_TEST_MODULES.match("/".join(inside))
    if parts[0] == "site-packages":
        return True                                         # numpy.libs, the distribution's metadata
    name = _module_name(parts[-1] if parts[0] == "__pycache__" else parts[0])
    return name in STDLIB_IMPORTED | STDLIB_MARGIN or name.startswith("_sysconfigdata")


#: libraries of the system that are not bundled: glibc's and the C++ runtime (which a C++ host loads itself)
SYSTEM_LIBRARIES = re.compile(r"^(libc|libm|libdl|libpthread|librt|libutil|libresolv|libcrypt|ld-linux[-\w]*|"
                              r"libstdc\+\+|libgcc_s)\.so")


@dataclass
class Runtime:
    """A staged runtime: the archive of its files and what it needs of the target system.

    Attributes
    ----------
    archive : Path
        Zip of the tree, entries under ``binaries/<platform>/python/``.
    python : str
        Version of the interpreter (X.Y.Z).
    packages : dict
        Bundled packages and their versions (numpy, and numba with llvmlite where chosen).
    glibc : str
        The newest glibc version any bundled file needs (the floor), ``"2.34"``.
    glibcxx : str
        The newest libstdc++ symbol version any bundled file needs, or "" when none needs it.
    library : str
        File name of libpython in ``python/lib``.
    """
    archive: Path
    python: str
    packages: dict = field(default_factory=dict)
    glibc: str = ""
    glibcxx: str = ""
    library: str = ""


# ---- ELF: the version needs and the run-time search path ---------------------------------------
def _elf_sections(data: bytes):
    """Section headers of a 64-bit little-endian ELF file: list of (type, offset, size, link)."""
    if data[:4] != b"\x7fELF" or data[4] != 2 or data[5] != 1:
        return None
    shoff, = struct.unpack_from("<Q", data, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", data, 0x3A)
    sections = []
    for i in range(shnum):
        _, sh_type, _, _, offset, size, link = struct.unpack_from("<IIQQQQI", data, shoff + i * shentsize)
        sections.append((sh_type, offset, size, link))
    return sections


def _string(data: bytes, table_offset: int, index: int) -> str:
    end = data.index(b"\0", table_offset + index)
    return data[table_offset + index:end].decode()


def version_needs(path) -> dict[str, list[str]]:
    """The symbol versions an ELF file needs, per library: ``{"libc.so.6": ["GLIBC_2.2.5", ...]}``
    (its ``.gnu.version_r`` section, SHT_GNU_verneed); empty for a file that is no ELF."""
    data = Path(path).read_bytes()
    sections = _elf_sections(data)
    needs: dict[str, list[str]] = {}
    for sh_type, offset, size, link in sections or ():
        if sh_type != 0x6FFFFFFE:                       # SHT_GNU_verneed
            continue
        strtab = sections[link][1]
        entry = offset
        while True:
            _, count, file_name, aux, next_entry = struct.unpack_from("<HHIII", data, entry)
            names = needs.setdefault(_string(data, strtab, file_name), [])
            a = entry + aux
            for _ in range(count):
                _, _, _, name, next_aux = struct.unpack_from("<IHHII", data, a)
                names.append(_string(data, strtab, name))
                a += next_aux
            if not next_entry:
                break
            entry += next_entry
    return needs


def _dynamic_entries(data):
    """(tag, value, string table offset) of each entry of an ELF file's dynamic section."""
    sections = _elf_sections(bytes(data))
    for sh_type, offset, size, link in sections or ():
        if sh_type != 6:                                # SHT_DYNAMIC
            continue
        for k in range(0, size, 16):
            tag, value = struct.unpack_from("<qQ", data, offset + k)
            if tag == 0:
                break
            yield tag, value, sections[link][1]


def needed_libraries(path) -> list[str]:
    """The DT_NEEDED entries of an ELF file (library names)."""
    data = Path(path).read_bytes()
    return [_string(data, strtab, value) for tag, value, strtab in _dynamic_entries(data) if tag == 1]


def runpath(path) -> str | None:
    """The RUNPATH (or RPATH) of an ELF file, None where it has none."""
    data = Path(path).read_bytes()
    return next((_string(data, strtab, value) for tag, value, strtab in _dynamic_entries(data)
                 if tag in (15, 29)), None)                # DT_RPATH, DT_RUNPATH


def set_runpath(path, new_path: str) -> None:
    """Overwrite the RUNPATH (and RPATH) string of an ELF file in place with ``new_path``, padded
    with NUL bytes (the string table keeps its size); it must not be longer than the old one."""
    data = bytearray(Path(path).read_bytes())
    for tag, value, strtab in list(_dynamic_entries(data)):
        if tag in (15, 29):
            start = strtab + value
            old = data[start:data.index(b"\0", start)]
            new = new_path.encode()
            if len(new) > len(old):
                raise ValueError(f"{path}: the new run-time path {new_path!r} is longer than the old {old.decode()!r}")
            data[start:start + len(old)] = new + b"\0" * (len(old) - len(new))
    Path(path).write_bytes(bytes(data))


def _version_key(version: str) -> tuple:
    return tuple(int(x) for x in re.findall(r"\d+", version))


def newest_version(needs: list[dict], prefix: str) -> str:
    """The newest version named ``prefix``X.Y over the files' needs (``"2.34"``), "" if none."""
    versions = [v[len(prefix):] for n in needs for names in n.values() for v in names if v.startswith(prefix)]
    versions = [v for v in versions if re.fullmatch(r"[\d.]+", v)]
    return max(versions, key=_version_key) if versions else ""


def scrub_paths(path, building_paths) -> int:
    """Overwrite every occurrence of a building machine's path in a file, but for its last
    component, with ``/`` characters (the file keeps its length). Returns the number of occurrences.

    The last component is kept because a linker merges a string constant with the tail of a longer
    one: libpython's version "3.11.7" is the tail of its compiled-in prefix ".../versions/3.11.7"."""
    data = Path(path).read_bytes()
    count = 0
    for p in sorted(building_paths, key=len, reverse=True):
        needle = p.encode()
        if needle in data:
            count += data.count(needle)
            head = needle.rindex(b"/") + 1
            data = data.replace(needle, b"/" * head + needle[head:])
    if count:
        Path(path).write_bytes(data)
    return count


def building_machine_paths() -> set[str]:
    """The absolute paths of this machine that files copied or compiled here can hold: the
    interpreter's prefixes, the project, the home folder's tools, the temporary folder's builds."""
    import site

    root = Path(__file__).resolve().parents[1]
    candidates = {str(root), sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix,
                  *site.getsitepackages(), str(Path(sys.executable).parent), tempfile.gettempdir() + "/slewing_",
                  sysconfig.get_config_var("prefix") or "", sysconfig.get_config_var("abs_builddir") or "",
                  sysconfig.get_config_var("abs_srcdir") or ""}
    home = os.path.expanduser("~")
    if home not in ("/", "") and len(home) > 5:
        candidates.add(home)
    return {p.rstrip("/") for p in candidates if p and p.startswith("/") and len(p.rstrip("/")) > 5}


# ---- the interpreter whose runtime is staged ------------------------------------------------------
#: what staging needs to know of an interpreter, asked of it (standard library only: it runs in that Python)
PROBE = r"""
import json, os, site, sys, sysconfig
from importlib import metadata

def probe(names):
    libdir, soname = sysconfig.get_config_var("LIBDIR") or "", sysconfig.get_config_var("INSTSONAME") or ""
    if not os.path.isfile(os.path.join(libdir, soname)):   # an installation moved since it was built: its prefix
        libdir = os.path.join(sys.base_prefix, "lib")
    packages, files = {}, {}
    for name in names:
        try:
            dist = metadata.distribution(name)
        except metadata.PackageNotFoundError:
            continue
        packages[name] = dist.version
        files[name] = [(str(dist.locate_file(f)), str(f)) for f in dist.files or ()]
    paths = [sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix, *site.getsitepackages(),
             os.path.dirname(sys.executable)] + [sysconfig.get_config_var(k) or "" for k in
                                                   ("prefix", "exec_prefix", "LIBDIR", "abs_builddir", "abs_srcdir")]
    return {"executable": sys.executable, "version": sys.version.split()[0], "sys_version": sys.version,
            "minor": "%d.%d" % sys.version_info[:2], "base_prefix": sys.base_prefix,
            "stdlib": sysconfig.get_path("stdlib"), "libdir": libdir, "soname": soname,
            "packages": packages, "files": files, "paths": paths}

if __name__ == "__main__":
    print(json.dumps(probe(json.loads(sys.argv[1]))))
"""

#: the distributions a runtime can carry
PACKAGES = ("numpy", "numba", "llvmlite")


def _is_running(python) -> bool:
    # not resolved: a virtual environment's python links to its base interpreter, which has other packages
    return python is None or os.path.abspath(python) == os.path.abspath(sys.executable)


def interpreter(python=None) -> dict:
    """What staging needs to know of the interpreter ``python`` (a path; None: the running one): its
    version, standard library, shared library, the numpy/numba/llvmlite it has and their files, and
    its prefixes. Another interpreter is asked in a subprocess (it may be built elsewhere, e.g. in a
    Debian 11 chroot by ``tests/linux_floor/build.sh``, and need not be able to import this file)."""
    if _is_running(python):
        namespace = {"__name__": "slewing_probe"}
        exec(PROBE, namespace)
        info = namespace["probe"](PACKAGES)
        info["running"] = True
        return info
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    run = subprocess.run([str(python), "-I", "-c", PROBE, json.dumps(PACKAGES)], capture_output=True, text=True,
                         env=env)
    if run.returncode != 0:
        raise RuntimeError(f"the runtime's interpreter {python} does not run here: {run.stderr.strip()[-600:]}")
    info = json.loads(run.stdout)
    info["running"] = False
    return info


# ---- the staged tree --------------------------------------------------------------------------
def _distribution_files(name: str, python: dict):
    """(path on this machine, path relative to site-packages) of an installed distribution's files."""
    for source, relative in python["files"][name]:
        source = Path(source)
        if relative.startswith("..") or not source.is_file():
            continue
        yield source, relative


def _strip(path: Path) -> None:
    strip = shutil.which("strip")
    if strip:
        subprocess.run([strip, "--strip-unneeded", str(path)], capture_output=True)


def _library_path(name: str, python: dict | None = None) -> Path | None:
    """Where library ``name`` is taken from: for the running interpreter where the dynamic loader
    finds it on this machine (``ldconfig -p``, in /sbin when it is not on PATH); for another one
    (``python``) only beside its libpython, where its builder put the libraries of its own system."""
    if python is not None and not python["running"]:
        found = Path(python["libdir"], name)
        return found if found.is_file() else None
    ldconfig = shutil.which("ldconfig") or next((p for p in ("/sbin/ldconfig", "/usr/sbin/ldconfig")
                                                  if os.path.exists(p)), None)
    if ldconfig:
        listing = subprocess.run([ldconfig, "-p"], capture_output=True, text=True).stdout
        for line in listing.splitlines():
            parts = line.strip().split(" => ")
            if len(parts) == 2 and parts[0].split(" ")[0] == name and "x86-64" in parts[0]:
                return Path(parts[1])
    return None


def python_library(python: dict | None = None) -> Path:
    """The shared library of the interpreter ``python`` (:func:`interpreter`; default this one): libpython3.X.so.1.0."""
    python = python or interpreter()
    library = Path(python["libdir"], python["soname"])
    if not library.is_file():
        raise RuntimeError(f"this Python ({python['base_prefix']}) has no shared library ({library}): a standalone FMU "
                           "needs a CPython built with --enable-shared (Debian's python3, pyenv with "
                           "PYTHON_CONFIGURE_OPTS=--enable-shared, the official Docker images), or build with "
                           "--runtime host")
    return library


def bundled_packages(numba: bool, python: dict | None = None) -> dict[str, str]:
    """The distributions a runtime carries, with their versions installed in ``python`` (default this one)."""
    python = python or interpreter()
    names = ["numpy"] + (["numba", "llvmlite"] if numba else [])
    versions = {}
    for name in names:
        if name in python["packages"]:
            versions[name] = python["packages"][name]
        else:
            raise RuntimeError(f"{name} is not installed in the Python {python['executable']}: a runtime with "
                               f"{'numba' if numba else 'numpy'} cannot be bundled; pip install {name}"
                               + ("" if name == "numpy" else ", or build without numba")) from None
    return versions


def stage_runtime(target: Path, numba: bool, python=None, trim: bool = True) -> dict:
    """Copy the runtime of the interpreter ``python`` (a path; default this one) into ``target`` (a
    Python prefix); returns its description (python, packages, glibc, glibcxx, library). ``trim``
    (without numba): only what the import audit found imported, and its margin (:func:`kept`)."""
    python = interpreter(python) if python is None or isinstance(python, (str, os.PathLike)) else python
    minor = python["minor"]
    packages = bundled_packages(numba, python)
    lib = target / "lib"
    stdlib_target = lib / f"python{minor}"
    stdlib = Path(python["stdlib"])
    stdlib_target.mkdir(parents=True)
    # the standard library
    for entry in stdlib.iterdir():
        if entry.name in STDLIB_EXCLUDED or entry.name.startswith(STDLIB_EXCLUDED_PREFIXES):
            continue
        if entry.is_dir():
            shutil.copytree(entry, stdlib_target / entry.name, ignore=shutil.ignore_patterns(
                "__pycache__", "test", "tests", "idle_test", "*.exe"))
        elif entry.suffix == ".py":
            shutil.copy2(entry, stdlib_target / entry.name)
    dynload = stdlib_target / "lib-dynload"
    for so in list(dynload.glob("*.so")):
        if DYNLOAD_EXCLUDED.match(so.name):
            so.unlink()
    # libpython
    library = python_library(python)
    shutil.copy2(library, lib / library.name)
    # the packages
    site_packages = stdlib_target / "site-packages"
    for name in packages:
        for source, relative in _distribution_files(name, python):
            if PACKAGE_EXCLUDED.search(relative) or relative.endswith((".dist-info/RECORD", "direct_url.json",
                                                                        "INSTALLER", "REQUESTED")):
                continue
            destination = site_packages / relative
            destination.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, destination)
    if trim and not numba:                  # what the import audit found unused (before the libraries they need)
        for f in sorted(target.rglob("*"), reverse=True):
            if f.is_file() and not kept(f.relative_to(target).as_posix(), minor):
                f.unlink()
            elif f.is_dir() and not any(f.iterdir()):
                f.rmdir()
    # ELF files: strip, search paths relative to $ORIGIN, the libraries they need beyond glibc
    elves = [p for p in target.rglob("*") if p.is_file() and p.read_bytes()[:4] == b"\x7fELF"]
    bundled = {p.name for p in elves}
    queue = list(elves)
    while queue:
        elf = queue.pop()
        for name in needed_libraries(elf):
            if name in bundled or SYSTEM_LIBRARIES.match(name):
                continue
            found = _library_path(name, python)
            if found is None:
                continue            # a library the module needs that this machine lacks: the module fails alike
            copy = lib / name
            shutil.copy2(found.resolve(), copy)
            bundled.add(name)
            elves.append(copy)
            queue.append(copy)
    for elf in elves:
        os.chmod(elf, 0o755)
        if site_packages not in elf.parents:       # the wheels' libraries are stripped (and strip breaks some)
            _strip(elf)
        if (runpath(elf) or "").startswith("/"):     # the building prefix: relative to the file instead
            relative = os.path.relpath(lib, elf.parent)
            set_runpath(elf, "$ORIGIN" if relative == "." else f"$ORIGIN/{relative}")
    paths = building_machine_paths()
    if not python["running"]:   # another interpreter's prefixes, build and install folders (not the system's own)
        paths |= {p.rstrip("/") for p in python["paths"] if p.startswith("/") and len(p.rstrip("/")) > 5
                  and not re.match(r"/(usr|lib|lib64|bin|sbin|etc)(/|$)", p)}
    for f in target.rglob("*"):
        if f.is_file():
            scrub_paths(f, paths)
    if minor == "%d.%d" % sys.version_info[:2]:     # the modules' bytecode (fmu_build.bytecode), for its Python
        compile_tree(stdlib_target, target)
    needs = [version_needs(elf) for elf in elves]
    return {"python": python["version"], "packages": packages, "library": library.name,
            "glibc": newest_version(needs, "GLIBC_"), "glibcxx": newest_version(needs, "GLIBCXX_")}


def runtime_key(numba: bool, platform_folder: str, python=None, trim: bool = True) -> str:
    """Cache key of a runtime: interpreter (``python``, a path or :func:`interpreter`'s answer; default this
    one), package versions, platform folder, this file's layout and this file's and :mod:`fmu_build.bytecode`'s
    contents."""
    python = interpreter(python) if python is None or isinstance(python, (str, os.PathLike)) else python
    text = json.dumps([LAYOUT, python["sys_version"], python["base_prefix"], bundled_packages(numba, python),
                       platform_folder, hashlib.sha256(Path(__file__).read_bytes()).hexdigest(),
                       hashlib.sha256((Path(__file__).parent / "bytecode.py").read_bytes()).hexdigest()]
                      + ([] if trim or numba else ["untrimmed"]))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def runtime_cache_dir() -> Path:
    """``$SLEWING_CACHE_DIR/fmu_runtime``, else ``~/.cache/slewing_model/fmu_runtime``."""
    base = os.environ.get("SLEWING_CACHE_DIR") or os.path.join(os.path.expanduser("~"), ".cache", "slewing_model")
    return Path(base) / "fmu_runtime"


def runtime(platform_folder: str, numba: bool = False, cache_dir=None, python=None, trim: bool = True) -> Runtime:
    """The runtime for an FMU's ``binaries/<platform>`` folder, staged and zipped once (cached).

    Parameters
    ----------
    platform_folder : str
        ``binaries/linux64`` (FMI 2.0) or ``binaries/x86_64-linux`` (FMI 3.0).
    numba : bool
        Also bundle numba and llvmlite (the compiled loops); numpy alone otherwise.
    cache_dir : path, optional
        Default :func:`runtime_cache_dir`.
    python : path, optional
        The interpreter whose runtime is carried (it must have numpy, and numba where asked; its
        libraries beyond glibc beside its libpython): default the running one. An interpreter built
        on an older system lowers the FMU's glibc floor (``tests/linux_floor/build.sh``).
    trim : bool
        Without numba: only the files the import audit found used, and their margin (:func:`kept`);
        False for the audit itself (``fmu_build/import_audit.py``).
    """
    if not sys.platform.startswith("linux"):
        raise RuntimeError(f"a standalone FMU is built on Linux only (this is {sys.platform}); its Windows "
                           "binary is built there too (docs/fmu/hosts.md, 'Windows: the win64 half')")
    cache = Path(cache_dir) if cache_dir else runtime_cache_dir()
    python = interpreter(python)
    key = runtime_key(numba, platform_folder, python, trim)
    archive = cache / f"runtime-{key}.zip"
    info = zipped_once(archive, lambda prefix: stage_runtime(prefix, numba, python, trim), platform_folder)
    return Runtime(archive=archive, **info)


def zipped_once(archive: Path, stage, platform_folder: str) -> dict:
    """A runtime staged by ``stage(prefix)`` (which returns its description, JSON data) and zipped with
    its entries under ``<platform_folder>/python/`` into ``archive``, its description beside it
    (``.json``), once: later calls read them (the Linux runtime's and, ``fmu_build.win64.runtime``, the
    win64 one's cache). The description is written first, the archive last, each whole
    (``os.replace``): a concurrent build that finds the archive finds its description complete.
    Returns the description."""
    description = archive.with_suffix(".json")
    if not archive.exists():
        archive.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(prefix="slewing_runtime_", dir=archive.parent) as tmp:
            prefix = Path(tmp) / RUNTIME_FOLDER
            info = stage(prefix)
            partial = Path(tmp) / "runtime.zip"
            with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED, compresslevel=6) as z:
                for f in sorted(prefix.rglob("*")):
                    if f.is_file():
                        z.write(f, f"{platform_folder}/{RUNTIME_FOLDER}/{f.relative_to(prefix).as_posix()}")
            partial_description = Path(tmp) / "runtime.json"
            partial_description.write_text(json.dumps(info))
            os.replace(partial_description, description)
            os.replace(partial, archive)
    return json.loads(description.read_text())
