"""The installed ``slewing`` command."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from slewing_model import Loads, load_bearing, solve

ROOT = Path(__file__).resolve().parents[1]
SLEWING = str(Path(sys.executable).with_name("slewing"))


def _run(*args):
    return subprocess.run([SLEWING, *args], capture_output=True, text=True, cwd=ROOT, timeout=300)


def test_solve_json_has_the_documented_fields_and_sign_convention():
    out = _run("solve", "examples/bearings/table3.toml", "--fz", "50000", "--mx", "2000", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert set(data["displacement"]) == {"x", "y", "z", "rx", "ry"}
    q = np.array(data["Q"])
    assert q.shape == (67, 4) and np.array(data["contact_angle"]).shape == (67, 4)
    assert np.array(data["interference"]).shape == (67, 2) and len(data["ball_angle"]) == 67
    assert data["iterations"] >= 1
    # --fz > 0 pushes the inner ring to +z and loads diagonal 1 (contacts 1 and 3)
    assert data["displacement"]["z"] > 0 and q[:, 0].min() > 0 and np.allclose(q[:, 0], q[:, 2])
    # the same numbers as the library
    ref = solve(load_bearing(ROOT / "examples/bearings/table3.toml"), Loads(Fz=5e4, Mx=2e3))
    assert np.allclose(q, ref.contact_load, rtol=1e-12)


def test_solve_table_is_readable():
    out = _run("solve", "examples/bearings/table3.toml", "--fz", "1e4")
    assert out.returncode == 0 and "max ball load" in out.stdout and len(out.stdout.splitlines()) == 67 + 5


def test_bad_definition_gives_a_clear_error(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((ROOT / "examples/bearings/table3.toml").read_text().replace("ball_count = 67", "ball_count = 500"))
    out = _run("solve", str(bad))
    assert out.returncode == 2
    assert "bearing.ball_count = 500: the balls do not fit the pitch circumference" in out.stderr
    assert "Traceback" not in out.stderr


def test_non_finite_load_option_is_refused():
    out = _run("solve", "examples/bearings/table3.toml", "--fz", "nan")
    assert out.returncode == 2 and "'nan' must be finite" in out.stderr


def test_solve_json_has_friction_torques_and_takes_mu_and_preload():
    from slewing_model.friction import catalogue_torque, friction_torque

    out = _run("solve", "examples/bearings/table3.toml", "--fz", "30000", "--mu", "0.08", "--preload", "5e-6", "--json")
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    bearing = load_bearing(ROOT / "examples/bearings/table3.toml").with_preload(5e-6)
    ref = solve(bearing, Loads(Fz=3e4))
    assert data["friction_torque"] == pytest.approx(friction_torque(bearing, ref, mu=0.08).magnitude, rel=1e-9)
    assert data["friction_torque_catalogue"] == pytest.approx(catalogue_torque(bearing, Loads(Fz=3e4)), rel=1e-12)
    assert np.allclose(data["Q"], ref.contact_load, rtol=1e-12)


def test_flexible_model_from_the_command_line(tmp_path):
    import os

    env = dict(os.environ, SLEWING_CACHE_DIR=str(tmp_path))
    out = subprocess.run([SLEWING, "solve", "examples/bearings/table3.toml", "--fz", "30000", "--model", "flexible",
                          "--bc", "clamped", "--json"], capture_output=True, text=True, cwd=ROOT, timeout=600, env=env)
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["model"] == "flexible" and np.array(data["ring_displacement"]).shape == (67, 4, 2)
    rigid = solve(load_bearing(ROOT / "examples/bearings/table3.toml"), Loads(Fz=3e4))
    assert data["displacement"]["z"] > rigid.displacement[2]  # flexible rings are softer


def test_plot_writes_a_png(tmp_path):
    import os

    env = dict(os.environ, SLEWING_CACHE_DIR=str(tmp_path))
    png = tmp_path / "fig.png"
    out = subprocess.run([SLEWING, "plot", "examples/bearings/table3.toml", "--preload", "2e-5", "--bc", "clamped",
                          "-o", str(png)], capture_output=True, text=True, cwd=ROOT, timeout=600, env=env)
    assert out.returncode == 0, out.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
