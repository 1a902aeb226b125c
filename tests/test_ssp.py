"""The pitch system SSP (examples/ssp/build_ssp.py) in three hosts against the Python co-simulation.

The SSP of the tests wires the table3 bearing FMU (rigid rings, the table3_fmu fixture), the pitch
drive FMU and the shipped blade-root series scaled to the small bearing, with a 5 deg command step.
Each host steps the FMUs side by side (Jacobi); run_manoeuvre follows the same step sequence with
coupling="parallel" (libcosim, ecos) or "parallel-zero-start" (fmpy: connections start at 0).

Tolerance 1e-9 of each signal's largest magnitude: the same FMUs take the same steps, and the only
differences left are the hosts' time values (fmpy adds up its steps, libcosim counts nanoseconds,
run_manoeuvre multiplies), one rounding apart, which move the interpolated loads by ~1e-16 and the
bearing's iterative solution by far less than its relative tolerance of 1e-9.
"""
import math
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description

from conftest import ROOT

sys.path.insert(0, str(ROOT / "examples" / "ssp"))
from ssp_hosts import (COMPARED, COUPLING, HOSTS, libtbb_missing, max_relative_difference,  # noqa: E402
                       reference_values)

T_ON, T_OFF, STOP, DT = 0.1, 0.9, 1.5, 0.01
STEP_DEG = 5.0
BEARING_PARAMETERS = {"load_frame": 2, "ring_model": 1, "preload": 10e-6}
TOLERANCE = 1e-9


def _command(t):
    return math.radians(STEP_DEG) if T_ON <= t < T_OFF else 0.0


@pytest.fixture(scope="module")
def system(table3_fmu, tmp_path_factory):
    """The SSP, its inputs and run_manoeuvre's results for each coupling."""
    sys.path.insert(0, str(ROOT))
    from build_ssp import build_ssp, step_command
    from fmu_build.drive import build_drive_fmu
    from slewing_drives import DriveParameters, LoadSeries
    from slewing_drives.cosimulation import run_manoeuvre

    folder = tmp_path_factory.mktemp("ssp")
    drive_fmu = build_drive_fmu(ROOT / "examples/drives/pitch_drive.toml", folder / "drive.fmu")
    shipped = LoadSeries.read_csv(ROOT / "examples/loads/blade_root_loads.csv")
    # the blade-root series of the 5-MW class pitch bearing, scaled to the small table3 bearing
    loads = LoadSeries(shipped.time, shipped.loads * np.array([0.02, 0.02, 0.02, 0.001, 0.001, 0.1]))
    ssp = build_ssp(folder / "pitch_system.ssp", table3_fmu, drive_fmu, loads,
                    step_command(STEP_DEG, T_ON, T_OFF), bearing_parameters=BEARING_PARAMETERS,
                    stop_time=STOP, step_size=DT)
    drive = DriveParameters.from_toml(ROOT / "examples/drives/pitch_drive.toml")
    references = {coupling: run_manoeuvre(table3_fmu, drive, loads, _command, t_end=STOP, dt=DT,
                                          start_values=BEARING_PARAMETERS, coupling=coupling)
                  for coupling in ("sequential", "parallel", "parallel-zero-start")}
    return ssp, references


def test_ssd_is_valid_and_connects_matching_units(system, tmp_path):
    from xml.etree import ElementTree

    from fmpy.ssp.ssd import read_ssd

    ssp, _ = system
    assert read_ssd(str(ssp)).version == "1.0"  # read_ssd validates against the SSP 1.0 schema
    ns = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
          "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon"}
    with zipfile.ZipFile(ssp) as z:
        root = ElementTree.fromstring(z.read("SystemStructure.ssd"))
        z.extractall(tmp_path)
    units = {u.get("name") for u in root.findall("ssd:Units/ssc:Unit", ns)}
    components = {c.get("name"): c for c in root.findall("ssd:System/ssd:Elements/ssd:Component", ns)}
    variables = {name: {v.name: v for v in read_model_description(str(tmp_path / c.get("source"))).modelVariables}
                 for name, c in components.items()}

    def unit(element, connector, kind):
        c = components[element].find(f"ssd:Connectors/ssd:Connector[@name='{connector}']", ns)
        assert c.get("kind") == kind
        fmu_variable = variables[element][connector]
        assert fmu_variable.causality == kind
        declared = c.find("ssc:Real", ns).get("unit")
        assert declared == fmu_variable.unit and declared in units, (element, connector)  # the FMU's own unit
        return declared

    connections = root.findall("ssd:System/ssd:Connections/ssd:Connection", ns)
    assert len(connections) == 10
    for c in connections:
        assert unit(c.get("startElement"), c.get("startConnector"), "output") == \
            unit(c.get("endElement"), c.get("endConnector"), "input")
    # every input of the drive and the bearing is connected
    ends = {(c.get("endElement"), c.get("endConnector")) for c in connections}
    for element in ("drive", "bearing"):
        inputs = {n for n, v in variables[element].items() if v.causality == "input"}
        assert inputs == {n for e, n in ends if e == element}, element


def test_run_has_motion_rate_limit_and_stick(system):
    # what the comparisons below go through: the ring moves at the rate limit, and sticks when it stops
    from slewing_drives import DriveParameters

    _, references = system
    r = references["parallel"]
    rate = DriveParameters.from_toml(ROOT / "examples/drives/pitch_drive.toml").rate_limit
    assert np.abs(r.speed).max() == pytest.approx(rate, rel=0.05)
    moving = np.flatnonzero(r.speed != 0.0)
    assert moving.size > 50 and np.any(r.speed[moving[0]:] == 0.0)
    assert r.friction_torque.min() > 0


def _host(name):
    if name == "libcosim":
        pytest.importorskip("libcosimpy")
    if name == "ecos":
        pytest.importorskip("ecospy")
        missing = libtbb_missing()     # the loader itself: no ldconfig on PATH needed
        if missing is not None:
            pytest.skip(f"{missing} (make installs it when run as root)")
    return HOSTS[name]


@pytest.mark.parametrize("host", list(HOSTS))
def test_ssp_run_equals_the_python_cosimulation(system, host):
    ssp, references = system
    run = _host(host)
    out = run(ssp, list(COMPARED), stop_time=STOP, step_size=DT)
    reference = references[COUPLING[host]]
    assert len(out["time"]) == len(reference.time)
    assert np.allclose(out["time"], reference.time, rtol=0, atol=1e-9)
    for name in COMPARED:
        assert max_relative_difference(out[name], reference_values(reference, name)) < TOLERANCE, name


def test_parallel_coupling_stays_close_to_the_sequential_one(system):
    # the hosts' Jacobi step delays the friction torque by one step; over this manoeuvre that moves the
    # angle by less than 1e-5 of its range (measured 6e-7) and the motor torque by less than 1e-4 (8e-6)
    _, references = system
    a, b = references["parallel"], references["sequential"]
    assert max_relative_difference(a.angle, b.angle) < 1e-5
    assert max_relative_difference(a.motor_torque, b.motor_torque) < 1e-4
    assert max_relative_difference(a.angle, b.angle) > 0  # but they are not the same sequence


def test_ecos_program_runs_the_ssp_in_a_minimal_environment(system, tmp_path):
    # ecos's own executable (C++), started with only PATH=/usr/bin:/bin and HOME and no LD_PRELOAD:
    # every FMU of the SSP (bearing, drive, tables) carries the Linux layer that loads its Python
    # (fmu_build.shim.install_python_shim); its last values equal run_manoeuvre's to ecos's six decimals
    _host("ecos")
    import ecospy

    program = Path(ecospy.__file__).parent / "binaries" / "ecos"
    if not program.is_file():
        pytest.skip(f"ecospy ships no ecos program at {program}")
    program.chmod(program.stat().st_mode | 0o111)
    ssp, references = system
    # TMPDIR: ecos unpacks the SSP into TMPDIR/ecos_ssp_* and leaves it; tmp_path is removed by pytest
    env = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", str(tmp_path)), "TMPDIR": str(tmp_path)}
    run = subprocess.run([str(program), "simulate", "--path", str(ssp), "--stepSize", str(DT), "--stopTime", str(STOP),
                          "--parameterSet", "pitch_system"], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    table = next(tmp_path.glob("*.csv"))
    with open(table) as fh:
        header = [h.strip() for h in fh.readline().split(",")]
        last = [float(v) for v in fh.read().strip().splitlines()[-1].split(",")]
    reference = references[COUPLING["ecos"]]
    # ecos writes the values at t = k dt before its last step; run_manoeuvre's k-th row is at (k + 1) dt
    at = int(np.argmin(np.abs(reference.time - last[header.index("time")])))
    assert abs(reference.time[at] - last[header.index("time")]) < 1e-9
    for host_name, column in (("drive.psi", "drive::psi[REAL]"),
                              ("bearing.friction_torque_magnitude", "bearing::friction_torque_magnitude[REAL]")):
        want = reference_values(reference, host_name)[at]
        assert last[header.index(column)] == pytest.approx(want, abs=1e-6 * max(1.0, abs(want))), host_name
