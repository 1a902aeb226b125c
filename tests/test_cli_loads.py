"""The ``slewing`` command as a new user meets it, and ``slewing loads``."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from openfast_files import write_binary
from slewing_drives.load_series import LoadSeries
from slewing_model import Loads, load_bearing, solve
from slewing_model.loads.aeroelastic import bearing_loads
from slewing_model.cli import _attach_negative_numbers

ROOT = Path(__file__).resolve().parents[1]
SLEWING = str(Path(sys.executable).with_name("slewing"))
DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "openfast"
V8 = DATA / "NREL5MW_Land_FASTv8_CertTest18_turb12mps_60s.outb"


def _run(*args):
    return subprocess.run([SLEWING, *args], capture_output=True, text=True, cwd=ROOT, timeout=300)


def test_missing_bearing_file_is_one_line_naming_it():
    out = _run("solve", "examples/bearings/no_such_bearing.toml", "--fz", "1e5")
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert out.stderr.strip().splitlines() == [
        "slewing solve: error: examples/bearings/no_such_bearing.toml: No such file or directory"]


def test_negative_scientific_numbers_are_taken_by_every_numeric_option():
    out = _run("solve", "examples/bearings/table3.toml", "--fz", "-1e5", "--mx", "-2.5e3", "--psi", "-.1", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    ref = solve(load_bearing(ROOT / "examples/bearings/table3.toml"), Loads(Fz=-1e5, Mx=-2.5e3), psi=-0.1)
    assert data["loads"]["Fz"] == -1e5 and np.allclose(data["Q"], ref.contact_load, rtol=1e-12)
    assert data["displacement"]["z"] < 0                           # pushed to -z: diagonal 2 carries it
    out = _run("solve", "examples/bearings/table3.toml", "--fz", "-inf")
    assert out.returncode == 2 and "'-inf' must be finite" in out.stderr


def test_negative_number_joining_leaves_other_arguments_alone():
    assert _attach_negative_numbers(["solve", "b.toml", "--fz", "-1e5", "--json"]) == \
        ["solve", "b.toml", "--fz=-1e5", "--json"]
    assert _attach_negative_numbers(["solve", "--fz=-1e5", "-o", "x"]) == ["solve", "--fz=-1e5", "-o", "x"]
    assert _attach_negative_numbers(["solve", "--", "-1e5"]) == ["solve", "--", "-1e5"]


def test_closed_pipe_ends_quietly():
    # like `slewing solve ... | head`: the reader closes the pipe before the command writes
    proc = subprocess.Popen([SLEWING, "solve", "examples/bearings/table3.toml", "--fz", "1e5"], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()
    stderr = proc.stderr.read().decode()
    assert proc.wait(timeout=300) == 141                           # the status of a command ended by SIGPIPE
    assert stderr == ""


def test_loads_command_writes_the_series_of_the_library(tmp_path):
    t = np.linspace(0.0, 4.0, 81)
    pitch = 2.0 + np.sin(t)
    b = np.column_stack([200 + 10 * t, -20 + t, 600 + 5 * t, 800 + 50 * np.sin(t), 8000 + 100 * t, 10 * np.cos(t)])
    names = ["Time", "RootFxb1", "RootFyb1", "RootFzb1", "RootMxb1", "RootMyb1", "RootMzb1", "BldPitch1"]
    units = ["s", "kN", "kN", "kN", "kN·m", "kN·m", "kN·m", "deg"]
    src = write_binary(tmp_path / "run.outb", t, names, units, np.column_stack([b, pitch]), 2)
    csv = tmp_path / "results" / "loads.csv"          # a folder not made yet, as results/ in a fresh clone
    out = _run("loads", str(src), "--bearing", "pitch", "--blade", "1", "--mounting", "hub", "--start", "1",
               "--end", "3", "-o", str(csv))
    assert out.returncode == 0, out.stderr
    assert "41 rows" in out.stdout
    lines = csv.read_text().splitlines()
    assert "time,Fx,Fy,Fz,Mx,My,Mz,psi,omega" in lines and "# load_frame = rotating" in lines
    back = LoadSeries.read_csv(csv)
    ref = bearing_loads(src, "pitch", 1, "hub", 1.0, 3.0)
    assert np.allclose(back.time, ref.time) and np.allclose(back.loads, ref.loads, rtol=1e-5)
    assert np.allclose(back.psi, ref.psi, rtol=1e-8) and np.allclose(back.omega, ref.omega, rtol=1e-5)
    assert np.allclose(back.psi, np.radians(pitch[(t >= 1 - 1e-9) & (t <= 3 + 1e-9)]), atol=1e-4)  # hub: psi = pitch


@pytest.mark.skipif(not V8.is_file(), reason=f"the real OpenFAST files are not here: {V8} is absent")
def test_loads_command_on_the_real_file_and_its_errors(tmp_path):
    csv = tmp_path / "pitch.csv"
    out = _run("loads", str(V8), "--bearing", "pitch", "-o", str(csv))
    assert out.returncode == 0, out.stderr
    assert "9601 rows" in out.stdout
    series = LoadSeries.read_csv(csv)
    assert series.loads[:, 4].mean() == pytest.approx(8126e3, abs=1e3)   # the data's README: RootMyb1 8126 kN m, in N m
    out = _run("loads", str(V8), "--bearing", "yaw", "-o", str(tmp_path / "yaw.csv"))
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert "YawPzn or NacYaw" in out.stderr and V8.name in out.stderr   # this file has no yaw angle channel
    out = _run("loads", str(tmp_path / "nope.outb"), "--bearing", "pitch", "-o", str(csv))
    assert out.returncode == 2 and "nope.outb: No such file or directory" in out.stderr
