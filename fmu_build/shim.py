"""The FMU's Linux binary: our layer in front of pythonfmu's (build time only; used by ``build_fmu.py``
and :mod:`fmu_build.drive`).

:func:`install_python_shim` compiles the layer (``fmu_src/shim/``) into a built FMU, in front of pythonfmu's
binary, and writes ``resources/python_runtime.txt``, the file that names the Python the FMU runs in: the
runtime a standalone FMU carries (:mod:`fmu_build.runtime`, with :mod:`fmu_build.win64` for its Windows
binary) or, for a host FMU, the building Python. It also writes ``resources/fmi_variables.tsv``
(:func:`variables_table`), the table of model variables the layer checks every get and set against.
"""
from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import warnings
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

from fmu_build.bytecode import bytecode, bytecode_path
from fmu_build.runtime import newest_version, version_needs

ROOT = Path(__file__).resolve().parents[1]
#: where the FMU's Python comes from: the runtime it carries, or the building Python
RUNTIMES = ("standalone", "host")
SHIM_DIR = ROOT / "fmu_src" / "shim"
#: C sources of the Linux binary, per FMI version: the FMI layer and the Python loader it calls
SHIM_SOURCES = {2: ("fmi2_shim.c", "python_runtime.c"), 3: ("fmi3_shim.c", "python_runtime.c")}
#: folder of the Linux x86-64 binary in the FMU, per FMI version
LINUX_BINARIES = {2: "binaries/linux64", 3: "binaries/x86_64-linux"}
#: name our layer gives pythonfmu's binary (it loads it from its own folder)
INNER_BINARY = "pythonfmu-export.so"
#: the one file of the FMU that names the Python it needs (read by the layer and by the slave)
PYTHON_RUNTIME_FILE = "python_runtime.txt"
PYTHON_HOME_VARIABLE = "SLEWING_FMU_PYTHONHOME"
#: the FMU's table of model variables (read by the layer: fmu_src/shim/shim_rules.h)
VARIABLES_FILE = "fmi_variables.tsv"
#: pythonfmu's and pythonfmu3's packages in the FMU import their FMU builder (argparse, zipfile, xml, ...:
#: 30-40 ms of every instantiation) for ``from pythonfmu import FmuBuilder``, which a running FMU never uses:
#: the line is left out of their ``__init__.py`` in the FMU
BUILDER_IMPORT = b"from .builder import FmuBuilder\n"
RUN_TIME_INITS = ("resources/pythonfmu/__init__.py", "resources/pythonfmu3/__init__.py")
#: their slave modules import pathlib, which they do not use, and xml for the model description, which a running
#: FMU never writes (with pathlib's urllib and ipaddress, about 10 ms of every instantiation): in the FMU the
#: first is left out and the second made lazy, ``Element`` and ``SubElement`` importing xml when first called
PATHLIB_IMPORT = b"from pathlib import Path\n"
XML_IMPORTS = {name: b"from xml.etree.ElementTree import " + name + b"\n"
               for name in (b"Element, SubElement", b"Element")}


def _lazy_xml(names: bytes) -> bytes:
    """What replaces ``from xml.etree.ElementTree import <names>`` in the FMU's copy of pythonfmu: functions of
    those names that import xml when first called."""
    return b"".join(b"def %s(*args, **kwargs):  # build_fmu.py: xml is imported where a model description is written\n"
                    b"    from xml.etree.ElementTree import %s as made\n"
                    b"    return made(*args, **kwargs)\n\n\n" % (name, name) for name in names.split(b", "))


#: the FMU's copies of pythonfmu's and pythonfmu3's modules: the lines left out or replaced (a line that is not
#: there, in another version of theirs, is left as it is)
RUN_TIME_EDITS = {
    **{init: ((BUILDER_IMPORT, b""),) for init in RUN_TIME_INITS},
    "resources/pythonfmu/fmi2slave.py": ((PATHLIB_IMPORT, b""), (XML_IMPORTS[b"Element, SubElement"],
                                                                 _lazy_xml(b"Element, SubElement"))),
    "resources/pythonfmu3/fmi3slave.py": ((PATHLIB_IMPORT, b""), (XML_IMPORTS[b"Element, SubElement"],
                                                                  _lazy_xml(b"Element, SubElement"))),
    **{f"resources/{module}": ((line, _lazy_xml(names)),)
       for module, names in (("pythonfmu/variables.py", b"Element, SubElement"),
                             ("pythonfmu3/variables.py", b"Element, SubElement"),
                             ("pythonfmu3/unit.py", b"Element"), ("pythonfmu3/variable_types.py", b"Element"))
       for line in (XML_IMPORTS[names],)},
}


def run_time_copy(name: str, data: bytes) -> bytes:
    """The FMU's copy of the file ``name`` (its path in the FMU): :data:`RUN_TIME_EDITS` made."""
    for line, replacement in RUN_TIME_EDITS.get(name, ()):
        data = data.replace(line, replacement)
    return data


#: FMI 2.0's type elements of a ScalarVariable
FMI2_TYPES = ("Real", "Integer", "Boolean", "String", "Enumeration")
#: the default causality and variability of a variable that states none (FMI 2.0 and 3.0)
DEFAULT_CAUSALITY, DEFAULT_VARIABILITY = "local", "continuous"


@contextlib.contextmanager
def installed_builder(package: str = "pythonfmu", script=None):
    """pythonfmu's (``package="pythonfmu3"``: pythonfmu3's) ``FmuBuilder`` from the installed package, for the
    length of a build of the slave ``script``.

    An FMU loaded in this process (fmpy runs one in-process) leaves its own modules in ``sys.modules``: its
    copy of the package, without the builder (:data:`BUILDER_IMPORT`) and with the FMU's binaries, first on
    ``sys.path`` too; and its copy of the slave, under the name the builder imports ``script`` by. For the
    build both are set aside, the installed package and ``script`` imported, and the FMU's modules come back
    after it."""
    import importlib
    import importlib.metadata

    loaded = sys.modules.get(package)
    foreign = loaded is not None and not hasattr(loaded, "FmuBuilder")       # an FMU's copy of the package
    slave = Path(script).stem if script is not None else None

    def an_fmus(name):
        if foreign and (name == package or name.startswith(package + ".")):
            return True
        module_file = getattr(sys.modules[name], "__file__", None) or ""
        return name == slave and os.path.realpath(module_file) != os.path.realpath(script)

    saved = {name: sys.modules[name] for name in list(sys.modules) if an_fmus(name)}
    for name in saved:
        del sys.modules[name]
    site = str(importlib.metadata.distribution(package).locate_file("")) if foreign else None
    if site:
        sys.path.insert(0, site)
    try:
        yield importlib.import_module(package).FmuBuilder
    finally:
        if site:
            sys.path.remove(site)
        for name in [name for name in sys.modules if name in saved or (foreign and (
                name == package or name.startswith(package + ".")))]:
            del sys.modules[name]
        sys.modules.update(saved)


def pythonfmu_build(script, package: str = "pythonfmu", **options):
    """``package``'s ``FmuBuilder.build_FMU(script, **options)`` with the installed builder
    (:func:`installed_builder`): the path it returns."""
    with installed_builder(package, script) as builder:
        return builder.build_FMU(script, **options)


def c_compiler() -> str:
    """The C compiler that builds the FMU's Linux binary: ``$CC``, else ``cc`` or ``gcc``.

    Raises RuntimeError naming what to install when there is none."""
    for name in filter(None, (os.environ.get("CC"), "cc", "gcc")):
        path = shutil.which(name)
        if path:
            return path
    raise RuntimeError(
        "building the FMU needs a C compiler for its Linux binary (the layer that loads Python in a C host): "
        "none found ($CC, cc, gcc). On Debian or Ubuntu: apt-get install gcc libc6-dev "
        "(`make` installs them when run as root).")


def compile_shim(output, fmi_version=2) -> Path:
    """Compile the FMU's Linux binary (``fmu_src/shim/``) into ``output``; returns its path.

    No debugging information and no search path is written into it: the binary holds no
    path of the building machine."""
    try:
        sources = [SHIM_DIR / name for name in SHIM_SOURCES[fmi_version]]
    except KeyError:
        raise ValueError(f"fmi_version = {fmi_version!r}: the Linux shim exists for FMI "
                         + ", ".join(map(str, SHIM_SOURCES))) from None
    output = Path(output)
    # libdl.so.2 named: on a glibc older than 2.34 dlopen lives there (glibc_compat.h)
    command = [c_compiler(), "-shared", "-fPIC", "-O2", "-g0", "-fvisibility=hidden", "-Wall", "-Wno-format-truncation",
               "-o", str(output), *map(str, sources), "-Wl,--no-as-needed", "-l:libdl.so.2", "-lpthread"]
    run = subprocess.run(command, capture_output=True, text=True, cwd=SHIM_DIR)
    if run.returncode != 0:
        raise RuntimeError(f"compiling the FMU's Linux binary failed ({' '.join(command)}):\n{run.stderr}")
    return output


def variables_table(model_description: bytes | str) -> str:
    """``resources/fmi_variables.tsv`` of an FMU, from its ``modelDescription.xml`` (FMI 2.0 or 3.0).

    One line per model variable,
    ``value_reference<TAB>type<TAB>causality<TAB>variability<TAB>initial<TAB>name<TAB>n_values``,
    the type as the modelDescription names it (FMI 2.0: Real, Integer, Boolean, String, Enumeration;
    FMI 3.0: Float64, Int32, Boolean, ...), ``initial`` empty where the description states none, and the
    standard's defaults where a variable states none: causality local, variability continuous for a Real
    (FMI 2.0) or float (FMI 3.0) variable and discrete for the others. ``n_values`` is the variable's
    number of values: 1 for a scalar, the product of the ``start`` of its ``Dimension`` elements for an
    FMI 3.0 array, 0 where a structural parameter sizes a dimension (not known before run time). Lines
    starting with ``#`` are comments. Raises ValueError where the description has no model variables or a
    variable lacks its name or value reference, or a dimension has neither a valid start nor a value
    reference."""
    root = ET.fromstring(model_description)
    version = root.get("fmiVersion", "")
    variables = root.find("ModelVariables")
    if variables is None:
        raise ValueError("the modelDescription has no ModelVariables")
    lines = [f"# model variables of {root.get('modelName', '')} (FMI {version}), written by build_fmu.py from "
             "modelDescription.xml\n",
             "# value_reference\ttype\tcausality\tvariability\tinitial\tname\tn_values\n"]
    for element in variables:
        if element.tag == "ScalarVariable":                       # FMI 2.0
            typed = next((child for child in element if child.tag in FMI2_TYPES), None)
            if typed is None:
                raise ValueError(f"variable {element.get('name')!r} has no type element")
            kind = typed.tag
            default_variability = DEFAULT_VARIABILITY if kind == "Real" else "discrete"
        else:                                                     # FMI 3.0: the element is the type
            kind = element.tag
            default_variability = DEFAULT_VARIABILITY if kind.startswith("Float") else "discrete"
        name, reference = element.get("name"), element.get("valueReference")
        if not name or reference is None or not reference.isdigit():
            raise ValueError(f"model variable {name!r}: no name or no valid valueReference ({reference!r})")
        if any(c in name for c in "\t\r\n"):
            raise ValueError(f"model variable {name!r}: a tab or line break in its name")
        n_values = 1
        for dimension in element.findall("Dimension"):                 # FMI 3.0 arrays
            start = dimension.get("start")
            if start is not None and start.isdigit():
                n_values *= int(start)
            elif start is None and dimension.get("valueReference") is not None:
                n_values = 0                                          # sized by a structural parameter
                break
            else:
                raise ValueError(f"model variable {name!r}: a Dimension without a valid start ({start!r}) "
                                 "or valueReference")
        lines.append("\t".join((reference, kind, element.get("causality", DEFAULT_CAUSALITY),
                                element.get("variability", default_variability), element.get("initial", ""),
                                name, str(n_values))) + "\n")
    return "".join(lines)


def python_runtime() -> dict[str, str]:
    """The Python an FMU built here runs its model in, as written to ``resources/python_runtime.txt``:
    ``version``, ``home`` (the installation's prefix), ``library`` (its libpython) and
    ``environment`` (the prefix with numpy: a virtual environment, or the home)."""
    libdir, soname = sysconfig.get_config_var("LIBDIR"), sysconfig.get_config_var("INSTSONAME")
    library = Path(libdir or "", soname or f"libpython{sys.version_info[0]}.{sys.version_info[1]}.so.1.0")
    if not library.exists():
        warnings.warn(f"this Python ({sys.base_prefix}) has no shared library ({library}): the FMU will run in "
                      f"Python hosts (fmpy) only, unless {PYTHON_HOME_VARIABLE} names another Python", stacklevel=2)
    return {"version": sys.version.split()[0], "home": sys.base_prefix, "library": str(library),
            "environment": sys.prefix}


def install_python_shim(fmu, model_identifier, fmi_version=2, runtime="standalone", numba=False, win64=True,
                        win64_numba=False, stage=None, extra_needs=(), runtime_python=None,
                        export_library=None) -> dict:
    """Put our Linux binary in front of pythonfmu's in the built ``fmu`` (rewritten in place), and
    for a standalone FMU the Python runtime beside it.

    pythonfmu's binary becomes ``INNER_BINARY``; ours, compiled here, takes the model
    identifier's name and starts the Python that ``resources/python_runtime.txt`` (written here)
    describes before it: the runtime the FMU carries (``binaries/<platform>/python``,
    :mod:`fmu_build.runtime`), or for ``runtime="host"`` the building Python. The file also states the
    FMU's glibc floor: the newest glibc version any of its Linux binaries needs.

    With ``win64`` (the default) a standalone FMU also gets a standalone Windows binary
    (:mod:`fmu_build.win64`: our layer cross-compiled with mingw-w64 in front of pythonfmu's DLL, the
    embeddable CPython with numpy beside it); the file then also says ``win64_version``,
    ``win64_library`` and ``win64_packages``. Otherwise, and for ``runtime="host"``, the Windows
    binary is left as pythonfmu wrote it (a tool coupling DLL). Returns what the file says, as a dict.
    ``stage``, where given, is called with one line as each stage begins (as in :func:`build_fmu.build_fmu`);
    ``extra_needs``: the glibc versions other binaries of the FMU need (:func:`fmu_build.runtime.version_needs`
    of the loops compiled ahead of time), part of the floor; ``runtime_python`` and ``export_library``
    are :func:`build_fmu.build_fmu`'s."""
    say = stage or (lambda line: None)
    if runtime not in RUNTIMES:
        raise ValueError(f"runtime = {runtime!r}: must be one of {', '.join(RUNTIMES)}")
    fmu = Path(fmu)
    folder = LINUX_BINARIES[fmi_version]
    binary = f"{folder}/{model_identifier}.so"
    win64 = bool(win64) and runtime == "standalone"
    with tempfile.TemporaryDirectory(prefix="slewing_shim_") as tmp:
        tmp = Path(tmp)
        say("compiling the FMU's Linux binary (C compiler) ...")
        shim = compile_shim(tmp / f"{model_identifier}.so", fmi_version)
        rewritten = tmp / "rewritten.fmu"
        with zipfile.ZipFile(fmu) as src:
            if binary not in src.namelist():
                raise RuntimeError(f"{fmu} has no {binary}: is it a pythonfmu FMU of {model_identifier}?")
            table = variables_table(src.read("modelDescription.xml"))
            inner = tmp / INNER_BINARY
            inner.write_bytes(Path(export_library).read_bytes() if export_library else src.read(binary))
            needs = [version_needs(inner), version_needs(shim), *extra_needs]
            if runtime == "standalone":
                from fmu_build.runtime import runtime as bundled_runtime

                say(f"staging the FMU's Python runtime (the interpreter, its standard library, numpy"
                    f"{', numba' if numba else ''}; read from its cache when staged before) ...")
                carried = bundled_runtime(folder, numba=numba, python=runtime_python)
                minor = f"{sys.version_info[0]}.{sys.version_info[1]}"
                if not carried.python.startswith(minor + "."):
                    raise RuntimeError(f"the runtime's Python {runtime_python} is {carried.python}, this one {minor}: "
                                       "the FMU's code and numba's cache are built here for one minor version")
                described = {"runtime": "standalone", "folder": "python", "library": carried.library,
                             "version": carried.python,
                             "packages": " ".join(f"{k}=={v}" for k, v in carried.packages.items())}
                base = carried.archive
                if win64:
                    import fmu_build.win64

                    say("adding the Windows (win64) binary: our layer cross-compiled with mingw-w64, the "
                        f"embeddable CPython and numpy{', numba' if win64_numba else ''} (read from its cache when "
                        "staged before) ...")
                    with zipfile.ZipFile(fmu) as stock:
                        windows = fmu_build.win64.windows_entries(stock, model_identifier, fmi_version, tmp)
                    base, win = fmu_build.win64.merged_archive(carried.archive, fmi_version, numba=win64_numba)
                    described.update({"platforms": "linux64 win64", "win64_version": win["version"],
                                      "win64_library": win["library"], "win64_packages": win["packages"]})
                shutil.copy2(base, rewritten)        # the runtimes' entries, compressed once
                floor = {"glibc": carried.glibc, "glibcxx": carried.glibcxx}
            else:
                described = {"runtime": "host", **python_runtime()}
                floor = {"glibc": "", "glibcxx": ""}
            floor = {key: max(filter(None, [floor[key], newest_version(needs, key.upper() + "_")]),
                              key=lambda v: tuple(map(int, v.split("."))), default="") for key in floor}
            described.update(floor)
            header = ("# The Python this FMU runs its model in (written by build_fmu.py).\n"
                      + ("# standalone: the runtime in binaries/<platform>/<folder>, found relative to the binary;\n"
                         "# the machine needs Linux x86-64 with glibc >= the floor below, nothing else"
                         + (", or 64-bit Windows\n# (binaries/win64: Python win64_version with win64_packages and the "
                            "Visual C++ runtime).\n" if win64 else ".\n")
                         if runtime == "standalone" else
                         f"# host: on a machine where this Python lives elsewhere, set {PYTHON_HOME_VARIABLE} to a\n"
                         "# Python installation or virtual environment with numpy (same minor version).\n"))
            with zipfile.ZipFile(rewritten, "a", zipfile.ZIP_DEFLATED) as dst:
                for info in src.infolist():
                    if info.filename == binary:
                        dst.write(inner, f"{folder}/{INNER_BINARY}")
                    elif win64 and info.filename in windows:
                        continue                          # pythonfmu's DLL: written below, behind our layer
                    elif not info.filename.endswith((PYTHON_RUNTIME_FILE, VARIABLES_FILE)):
                        data = run_time_copy(info.filename, src.read(info.filename))
                        dst.writestr(info, data)
                        if info.filename.startswith("resources/") and info.filename.endswith(".py"):
                            # its bytecode, naming the module by its path in resources/ (fmu_build.bytecode)
                            code = bytecode(data, info.filename[len("resources/"):])
                            if code is not None:
                                dst.writestr(bytecode_path(info.filename), code)
                dst.write(shim, binary)
                for name, path in (windows.items() if win64 else ()):
                    dst.write(path, name)
                dst.writestr(f"resources/{PYTHON_RUNTIME_FILE}",
                             header + "".join(f"{k}={v}\n" for k, v in described.items()))
                dst.writestr(f"resources/{VARIABLES_FILE}", table)
        shutil.move(str(rewritten), fmu)
    return described

