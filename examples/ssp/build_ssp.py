"""The pitch system as an SSP (System Structure and Parameterization 1.0).

Four FMUs (FMI 2.0 co-simulation), connected with units:

* ``loads``: the blade-root load series ``examples/loads/blade_root_loads.csv``
  (a time table, linear interpolation: Fx, Fy, Fz, Mx, My, Mz);
* ``command``: the pitch angle command of ``make demo`` (5 deg from 1 s to 6 s);
* ``drive``: the electric pitch drive (``fmu_build/drive.py``, ``examples/drives/pitch_drive.toml``);
* ``bearing``: the pitch bearing (``build_fmu.py``, ``examples/bearings/pitch_bearing.toml``).

Connections: loads.Fx..My -> bearing.Fx..My (blade frame: the bearing's
``load_frame`` = 2, set in the SSP); loads.Mz -> drive.load_moment;
command.command -> drive.command; drive.psi, drive.omega -> bearing.psi,
bearing.omega; bearing.friction_torque_magnitude -> drive.friction_torque.

    .venv/bin/python examples/ssp/build_ssp.py [--rigid] [-o examples/ssp/pitch_system.ssp]

The .ssp holds the FMUs (the bearing's with its superelement: megabytes), so it
is built by this command and not kept in git.
"""
from __future__ import annotations

import argparse
import math
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement, tostring

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"

#: SSP units: name -> exponents of (kg, m, s, A, rad)
UNITS = {"N": (1, 1, -2, 0, 0), "N.m": (1, 2, -2, 0, 0), "rad": (0, 0, 0, 0, 1), "rad/s": (0, 0, -1, 0, 1),
         "A": (0, 0, 0, 1, 0)}

LOAD_COLUMNS = [("Fx", "N", "force on the blade root along x (blade frame)"),
                ("Fy", "N", "force on the blade root along y (blade frame)"),
                ("Fz", "N", "force on the blade root along the pitch axis"),
                ("Mx", "N.m", "moment on the blade root about x (blade frame)"),
                ("My", "N.m", "moment on the blade root about y (blade frame)"),
                ("Mz", "N.m", "moment about the pitch axis, on the drive")]

#: (start element, start connector, end element, end connector, unit)
CONNECTIONS = ([("loads", name, "bearing", name, unit) for name, unit, _ in LOAD_COLUMNS[:5]]
               + [("loads", "Mz", "drive", "load_moment", "N.m"),
                  ("command", "command", "drive", "command", "rad"),
                  ("drive", "psi", "bearing", "psi", "rad"),
                  ("drive", "omega", "bearing", "omega", "rad/s"),
                  ("bearing", "friction_torque_magnitude", "drive", "friction_torque", "N.m")])

#: outputs that are not connected but are worth recording, as connectors: element -> (name, unit)
RECORDED = {"drive": [("motor_torque", "N.m"), ("motor_current", "A"), ("ring_torque", "N.m")],
            "bearing": [("friction_torque", "N.m"), ("max_ball_load", "N"), ("static_safety_factor", None)]}


def step_command(step_deg: float, t_on: float, t_off: float):
    """The pitch command as a step table: (time s, angle rad) rows, each held until the next."""
    return [0.0, t_on, t_off], [[0.0], [math.radians(step_deg)], [0.0]]


def build_ssp(output, bearing_fmu, drive_fmu, loads, command_table, *, bearing_parameters: dict,
              stop_time: float, step_size: float, drive_parameters: dict | None = None) -> Path:
    """Write the SSP; returns its path.

    Parameters
    ----------
    output : path
        The ``.ssp`` file.
    bearing_fmu, drive_fmu : path
        FMI 2.0 FMUs of ``build_fmu.py`` and ``fmu_build/drive.py``.
    loads : slewing_drives.LoadSeries
        Bearing loads (Fx..My) and load moment (Mz) against time.
    command_table : (times, rows)
        Angle command, rad, as a step table (:func:`step_command`).
    bearing_parameters, drive_parameters : dict
        Parameter values bound in the SSP (name -> int or float).
    stop_time, step_size : float, s
        The SSP's DefaultExperiment (the step size in the OSP annotation libcosim reads).
    """
    from fmu_build.drive import build_table_fmu

    output = Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="pitch_ssp_") as tmp:
        tmp = Path(tmp)
        load_fmu = build_table_fmu(tmp / "loads.fmu", "blade-root loads", loads.time, LOAD_COLUMNS, loads.loads)
        times, rows = command_table
        command_fmu = build_table_fmu(tmp / "command.fmu", "pitch angle command", times,
                                      [("command", "rad", "pitch angle command")], rows, interpolation="previous")
        ssd = _system_description(stop_time, step_size, bearing_parameters, drive_parameters or {})
        with zipfile.ZipFile(output, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("SystemStructure.ssd", ssd)
            for name, path in (("loads", load_fmu), ("command", command_fmu), ("drive", drive_fmu),
                               ("bearing", bearing_fmu)):
                z.write(path, f"resources/{name}.fmu")
    return output


def _system_description(stop_time, step_size, bearing_parameters, drive_parameters) -> bytes:
    root = Element(f"{{{SSD}}}SystemStructureDescription", version="1.0", name="pitch_system")
    system = SubElement(root, f"{{{SSD}}}System", name="pitch_system",
                        description="pitch drive and pitch bearing under blade-root loads")
    elements = SubElement(system, f"{{{SSD}}}Elements")
    connectors: dict[str, list] = {"loads": [], "command": [], "drive": [], "bearing": []}
    for start, out, end, inp, unit in CONNECTIONS:
        connectors[start].append((out, "output", unit))
        connectors[end].append((inp, "input", unit))
    for element, names in RECORDED.items():
        connectors[element] += [(name, "output", unit) for name, unit in names]
    parameters = {"bearing": bearing_parameters, "drive": drive_parameters}
    for name in ("loads", "command", "drive", "bearing"):
        component = SubElement(elements, f"{{{SSD}}}Component", name=name,
                               type="application/x-fmu-sharedlibrary", source=f"resources/{name}.fmu")
        block = SubElement(component, f"{{{SSD}}}Connectors")
        seen = set()
        for connector, kind, unit in connectors[name]:
            if (connector, kind) in seen:
                continue
            seen.add((connector, kind))
            c = SubElement(block, f"{{{SSD}}}Connector", name=connector, kind=kind)
            SubElement(c, f"{{{SSC}}}Real", **({"unit": unit} if unit else {}))
        if parameters.get(name):
            bindings = SubElement(component, f"{{{SSD}}}ParameterBindings")
            values = SubElement(SubElement(bindings, f"{{{SSD}}}ParameterBinding"), f"{{{SSD}}}ParameterValues")
            pset = SubElement(values, f"{{{SSV}}}ParameterSet", version="1.0", name="pitch_system")
            plist = SubElement(pset, f"{{{SSV}}}Parameters")
            for key, value in parameters[name].items():
                p = SubElement(plist, f"{{{SSV}}}Parameter", name=key)
                SubElement(p, f"{{{SSV}}}Integer" if isinstance(value, int) else f"{{{SSV}}}Real", value=repr(value))
    connections = SubElement(system, f"{{{SSD}}}Connections")
    for start, out, end, inp, _ in CONNECTIONS:
        SubElement(connections, f"{{{SSD}}}Connection", startElement=start, startConnector=out, endElement=end,
                   endConnector=inp)
    units = SubElement(root, f"{{{SSD}}}Units")
    for name, exponents in UNITS.items():
        unit = SubElement(units, f"{{{SSC}}}Unit", name=name)
        SubElement(unit, f"{{{SSC}}}BaseUnit", {k: str(v) for k, v in zip(("kg", "m", "s", "A", "rad"), exponents) if v})
    SubElement(root, f"{{{SSD}}}DefaultExperiment", startTime="0.0", stopTime=repr(float(stop_time)))
    from xml.etree.ElementTree import register_namespace

    for prefix, uri in (("ssd", SSD), ("ssc", SSC), ("ssv", SSV)):
        register_namespace(prefix, uri)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root)


def build_pitch_system(output=None, *, ring_model: int = 2, bearing_fmu=None, drive_fmu=None) -> Path:
    """The SSP of ``make demo``'s pitch manoeuvre (examples/pitch_manoeuvre.py): builds the FMUs it needs."""
    sys.path.insert(0, str(ROOT / "examples"))
    import pitch_manoeuvre as demo
    from build_fmu import build_fmu
    from fmu_build.drive import build_drive_fmu
    from slewing_drives import LoadSeries

    output = Path(output) if output else ROOT / "examples" / "ssp" / "pitch_system.ssp"
    bearing_fmu = bearing_fmu or build_fmu(ROOT / "examples/bearings/pitch_bearing.toml",
                                           ROOT / "build/SlewingBearing_pitch_bearing.fmu")
    drive_fmu = drive_fmu or build_drive_fmu(ROOT / "examples/drives/pitch_drive.toml",
                                             ROOT / "build/SlewingDrive_pitch_drive.fmu")
    loads = LoadSeries.read_csv(ROOT / "examples/loads/blade_root_loads.csv")
    return build_ssp(output, bearing_fmu, drive_fmu, loads, step_command(demo.STEP_DEG, demo.T_ON, demo.T_OFF),
                     bearing_parameters=dict(PITCH_BEARING_PARAMETERS, ring_model=ring_model),
                     stop_time=demo.T_END, step_size=demo.DT)


#: the bearing parameters of make demo: blade-root loads turn with the blade (load_frame 2)
PITCH_BEARING_PARAMETERS = {"load_frame": 2, "ring_model": 2, "friction_coefficient": 0.1}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", default=str(ROOT / "examples" / "ssp" / "pitch_system.ssp"))
    parser.add_argument("--rigid", action="store_true", help="rigid rings (faster) instead of flexible rings")
    args = parser.parse_args(argv)
    print(f"wrote {build_pitch_system(args.output, ring_model=1 if args.rigid else 2)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
