"""The Python runtime a standalone FMU carries (build time only; used by ``build_fmu.py``).

A standalone FMU runs its model on a machine that has no Python: it carries the building
interpreter's shared library, the part of the standard library a numpy model uses, numpy and,
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
  layer can refuse an older system with a message instead of a loader error.

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
from importlib import metadata
from pathlib import Path

#: the folder of the runtime inside ``binaries/<platform>/``
RUNTIME_FOLDER = "python"
#: version of this file's layout: part of the cache key
LAYOUT = 4

#: standard-library folders and modules a numpy model never imports (tests, GUIs, installers, build files)
STDLIB_EXCLUDED = {"test", "tkinter", "idlelib", "turtledemo", "ensurepip", "lib2to3", "pydoc_data",
                   "site-packages", "__pycache__", "venv", "turtle.py"}
STDLIB_EXCLUDED_PREFIXES = ("config-",)
#: extension modules left out: tests, terminals, GUIs, network security (libssl is no part of a bare system)
DYNLOAD_EXCLUDED = re.compile(r"^(_test|_xx|xxlimited|_ctypes_test|_tkinter|_curses|readline|nis|_ssl|_hashlib|"
                              r"_sqlite3|_crypt|ossaudiodev|spwd|audioop|_dbm|_gdbm)")
#: files left out of the packages: tests, type stubs, C headers and sources
PACKAGE_EXCLUDED = re.compile(r"(^|/)(tests?|__pycache__|include|_pyinstaller)(/|$)|\.(pyi|pxd|h|c|cpp)$")
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

    root = Path(__file__).resolve().parent
    candidates = {str(root), sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix,
                  *site.getsitepackages(), str(Path(sys.executable).parent), tempfile.gettempdir() + "/slewing_",
                  sysconfig.get_config_var("prefix") or "", sysconfig.get_config_var("abs_builddir") or "",
                  sysconfig.get_config_var("abs_srcdir") or ""}
    home = os.path.expanduser("~")
    if home not in ("/", "") and len(home) > 5:
        candidates.add(home)
    return {p.rstrip("/") for p in candidates if p and p.startswith("/") and len(p.rstrip("/")) > 5}


# ---- the staged tree --------------------------------------------------------------------------
def _distribution_files(name: str):
    """(path on this machine, path relative to site-packages) of an installed distribution's files."""
    dist = metadata.distribution(name)
    for f in dist.files or ():
        source = Path(dist.locate_file(f))
        relative = str(f)
        if relative.startswith("..") or not source.is_file():
            continue
        yield source, relative


def _strip(path: Path) -> None:
    strip = shutil.which("strip")
    if strip:
        subprocess.run([strip, "--strip-unneeded", str(path)], capture_output=True)


def _library_path(name: str) -> Path | None:
    """Where the dynamic loader finds library ``name`` on this machine (``ldconfig -p``, in /sbin
    when it is not on PATH)."""
    ldconfig = shutil.which("ldconfig") or next((p for p in ("/sbin/ldconfig", "/usr/sbin/ldconfig")
                                                  if os.path.exists(p)), None)
    if ldconfig:
        listing = subprocess.run([ldconfig, "-p"], capture_output=True, text=True).stdout
        for line in listing.splitlines():
            parts = line.strip().split(" => ")
            if len(parts) == 2 and parts[0].split(" ")[0] == name and "x86-64" in parts[0]:
                return Path(parts[1])
    return None


def python_library() -> Path:
    """The shared library of this interpreter (libpython3.X.so.1.0)."""
    library = Path(sysconfig.get_config_var("LIBDIR") or "", sysconfig.get_config_var("INSTSONAME") or "")
    if not library.is_file():
        raise RuntimeError(f"this Python ({sys.base_prefix}) has no shared library ({library}): a standalone FMU "
                           "needs a CPython built with --enable-shared (Debian's python3, pyenv with "
                           "PYTHON_CONFIGURE_OPTS=--enable-shared, the official Docker images), or build with "
                           "--runtime host")
    return library


def bundled_packages(numba: bool) -> dict[str, str]:
    """The distributions a runtime carries, with their installed versions."""
    names = ["numpy"] + (["numba", "llvmlite"] if numba else [])
    versions = {}
    for name in names:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            raise RuntimeError(f"{name} is not installed in this Python ({sys.prefix}): a runtime with "
                               f"{'numba' if numba else 'numpy'} cannot be bundled; pip install {name}"
                               + ("" if name == "numpy" else ", or build without numba")) from None
    return versions


def stage_runtime(target: Path, numba: bool) -> dict:
    """Copy this interpreter's runtime into ``target`` (a Python prefix); returns its description
    (python, packages, glibc, glibcxx, library)."""
    minor = f"{sys.version_info[0]}.{sys.version_info[1]}"
    packages = bundled_packages(numba)
    lib = target / "lib"
    stdlib_target = lib / f"python{minor}"
    stdlib = Path(sysconfig.get_path("stdlib"))
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
    library = python_library()
    shutil.copy2(library, lib / library.name)
    # the packages
    site_packages = stdlib_target / "site-packages"
    for name in packages:
        for source, relative in _distribution_files(name):
            if PACKAGE_EXCLUDED.search(relative) or relative.endswith((".dist-info/RECORD", "direct_url.json",
                                                                        "INSTALLER", "REQUESTED")):
                continue
            destination = site_packages / relative
            destination.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, destination)
    # ELF files: strip, search paths relative to $ORIGIN, the libraries they need beyond glibc
    elves = [p for p in target.rglob("*") if p.is_file() and p.read_bytes()[:4] == b"\x7fELF"]
    bundled = {p.name for p in elves}
    queue = list(elves)
    while queue:
        elf = queue.pop()
        for name in needed_libraries(elf):
            if name in bundled or SYSTEM_LIBRARIES.match(name):
                continue
            found = _library_path(name)
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
    for f in target.rglob("*"):
        if f.is_file():
            scrub_paths(f, paths)
    needs = [version_needs(elf) for elf in elves]
    return {"python": sys.version.split()[0], "packages": packages, "library": library.name,
            "glibc": newest_version(needs, "GLIBC_"), "glibcxx": newest_version(needs, "GLIBCXX_")}


def runtime_key(numba: bool, platform_folder: str) -> str:
    """Cache key of a runtime: interpreter, package versions, platform folder and this file's layout."""
    text = json.dumps([LAYOUT, sys.version, sys.base_prefix, bundled_packages(numba), platform_folder,
                       hashlib.sha256(Path(__file__).read_bytes()).hexdigest()])
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def runtime_cache_dir() -> Path:
    """``$SLEWING_CACHE_DIR/fmu_runtime``, else ``~/.cache/slewing_model/fmu_runtime``."""
    base = os.environ.get("SLEWING_CACHE_DIR") or os.path.join(os.path.expanduser("~"), ".cache", "slewing_model")
    return Path(base) / "fmu_runtime"


def runtime(platform_folder: str, numba: bool = False, cache_dir=None) -> Runtime:
    """The runtime for an FMU's ``binaries/<platform>`` folder, staged and zipped once (cached).

    Parameters
    ----------
    platform_folder : str
        ``binaries/linux64`` (FMI 2.0) or ``binaries/x86_64-linux`` (FMI 3.0).
    numba : bool
        Also bundle numba and llvmlite (the compiled loops); numpy alone otherwise.
    cache_dir : path, optional
        Default :func:`runtime_cache_dir`.
    """
    if not sys.platform.startswith("linux"):
        raise RuntimeError(f"a standalone FMU is built on Linux only (this is {sys.platform}); see the README's "
                           "'Windows' section for what a Windows build needs")
    cache = Path(cache_dir) if cache_dir else runtime_cache_dir()
    key = runtime_key(numba, platform_folder)
    archive, description = cache / f"runtime-{key}.zip", cache / f"runtime-{key}.json"
    if not archive.exists():
        cache.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(prefix="slewing_runtime_", dir=cache) as tmp:
            prefix = Path(tmp) / RUNTIME_FOLDER
            info = stage_runtime(prefix, numba)
            partial = Path(tmp) / "runtime.zip"
            with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED, compresslevel=6) as z:
                for f in sorted(prefix.rglob("*")):
                    if f.is_file():
                        z.write(f, f"{platform_folder}/{RUNTIME_FOLDER}/{f.relative_to(prefix)}")
            # the description first, the archive last, each whole (os.replace): a concurrent build that
            # finds the archive finds its description complete
            partial_description = Path(tmp) / "runtime.json"
            partial_description.write_text(json.dumps(info))
            os.replace(partial_description, description)
            os.replace(partial, archive)
    info = json.loads(description.read_text())
    return Runtime(archive=archive, **info)
