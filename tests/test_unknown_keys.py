"""Every table of a bearing file and of a study file refuses a key it does not know.

A misspelt key used to be ignored and its default used without a word (``[material]
youngs_modulus = 100.0`` gave the 200 GPa result). Each refusal names the file, the table,
the key and the known keys. The known keys below are written out from the file formats
documented in docs/guide/bearing-files.md, docs/guide/studies.md and
slewing_model/study/definition.py, not taken from the code.
"""
import re
import subprocess
import sys
from pathlib import Path

import pytest

from slewing_model import BearingDefinitionError, load_bearing
from slewing_model.study import StudyDefinitionError, load_study

ROOT = Path(__file__).resolve().parents[1]

BEARING = """[bearing]
name = "t"
pitch_diameter_mm = 541.0
ball_diameter_mm = 25.0
groove_radius_mm = 13.25
contact_angle_deg = 45.0
ball_count = 67
"""


def _refusal(load, path):
    with pytest.raises((BearingDefinitionError, StudyDefinitionError)) as info:
        load(path)
    return str(info.value)


def _assert_names(message, path, table, key, known):
    assert str(path) in message, message
    assert f"[{table}]" in message, message
    assert key in message, message
    for k in known:
        assert k in message, (k, message)


@pytest.mark.parametrize("extra, table, key, known", [
    ("[bearing]\n", "bearing", "pitch_diam_mm", ["pitch_diameter_mm", "ball_count", "preload_um"]),
    ("[material]\nyoungs_modulus = 100.0\n", "material", "youngs_modulus", ["youngs_modulus_gpa", "poisson_ratio"]),
    ("[rings]\ngap_mmm = 3\n", "rings", "gap_mmm", ["gap_mm", "outer_ring_height_mm", "inner_ring_bolted_face"]),
    ("[errors]\nouter_csv = 'x.csv'\n", "errors", "outer_csv", ["outer_ring_csv", "ball_diameters_csv", "synthetic"]),
    ("[errors.synthetic]\nseed = 1\nradial_amplitude = 3.0\n", "errors.synthetic", "radial_amplitude",
     ["radial_amplitude_um", "axial_amplitude_um", "waviness_orders", "ball_tolerance_um", "seed"]),
    ("[connection.outer]\ntype = 'tube'\ninner_diameter_mm = 560.0\nouter_diameter_mm = 620.0\nlength_mm = 400.0\n"
     "youngs_modulus_gpa = 210.0\npoisson_ratio = 0.3\nwall_thickness_mm = 30.0\n", "connection.outer",
     "wall_thickness_mm", ["inner_diameter_mm", "outer_diameter_mm", "length_mm", "youngs_modulus_gpa",
                           "axial_modulus_gpa", "hoop_modulus_gpa", "shear_modulus_gpa", "poisson_ratio"]),
    ("[connection]\nouter_ring = 1\n", "connection", "outer_ring", ["outer", "inner"]),
])
def test_bearing_file_table_refuses_unknown_key(tmp_path, extra, table, key, known):
    path = tmp_path / "bearing.toml"
    if table == "bearing":
        text = BEARING + f"{key} = 541.0\n"
    else:
        text = BEARING + "\n" + extra
    path.write_text(text)
    _assert_names(_refusal(load_bearing, path), path, table, key, known)


@pytest.mark.parametrize("name", ["materail", "Material", "RINGS"])
def test_bearing_file_refuses_unknown_table_case_sensitively(tmp_path, name):
    path = tmp_path / "bearing.toml"
    path.write_text(BEARING + f"\n[{name}]\nyoungs_modulus_gpa = 100.0\n")
    message = _refusal(load_bearing, path)
    _assert_names(message, path, name, name, ["[bearing]", "[material]", "[rings]", "[errors]"])
    assert "unknown table" in message


def test_cli_refuses_misspelt_material_key(tmp_path):
    path = tmp_path / "bearing.toml"
    path.write_text(BEARING + "\n[material]\nyoungs_modulus = 100.0\n")
    run = subprocess.run([sys.executable, "-m", "slewing_model.cli", "solve", str(path), "--fz", "1e4"],
                         capture_output=True, text=True, cwd=ROOT)
    assert run.returncode == 2, run.stdout
    assert "youngs_modulus" in run.stderr and "unknown key" in run.stderr and str(path) in run.stderr


STUDY = f"""[study]
name = "t"

[[loads]]
name = "idle"
constant = [0, 0, 0, 0, 0, 0]
omega_rad_s = 0.1
duration_s = 1.0
steps = 3

[bearings]
files = ["{(ROOT / 'examples/bearings/table3.toml').as_posix()}"]
ring_model = ["rigid"]
error_seeds = {{first = 1, count = 2}}

[bearings.synthetic_errors]
waviness_orders = [2, 3]

[simulation]
mesh = "coarse"
"""


@pytest.mark.parametrize("anchor, added, table, key, known", [
    ('name = "t"\n', "workers = 4\n", "study", "workers", ["name", "description", "base_dir"]),
    ("steps = 3\n", "step = 4\n", "loads[0]", "step", ["constant", "duration_s", "steps", "omega_rad_s", "name"]),
    ('ring_model = ["rigid"]\n', "ring_models = ['flexible']\n", "bearings", "ring_models",
     ["files", "ring_model", "preload_um", "friction_coefficient", "error_seeds", "synthetic_errors"]),
    ("waviness_orders = [2, 3]\n", "radial_amplitude = [1.0]\n", "bearings.synthetic_errors", "radial_amplitude",
     ["radial_amplitude_um", "axial_amplitude_um", "ball_tolerance_um", "waviness_orders"]),
    ('mesh = "coarse"\n', "bcs = 'free'\n", "simulation", "bcs", ["mesh", "bc", "seal_torque_Nm", "tolerance"]),
])
def test_study_file_table_refuses_unknown_key(tmp_path, anchor, added, table, key, known):
    path = tmp_path / "study.toml"
    assert anchor in STUDY
    path.write_text(STUDY.replace(anchor, anchor + added, 1))
    _assert_names(_refusal(load_study, path), path, table, key, known)


def test_study_error_seeds_table_refuses_unknown_key(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(STUDY.replace("{first = 1, count = 2}", "{first = 1, number = 2}"))
    _assert_names(_refusal(load_study, path), path, "bearings.error_seeds", "number", ["first", "count"])


@pytest.mark.parametrize("name", ["simulations", "Simulation"])
def test_study_file_refuses_unknown_table_case_sensitively(tmp_path, name):
    path = tmp_path / "study.toml"
    path.write_text(STUDY.replace("[simulation]", f"[{name}]"))
    message = _refusal(load_study, path)
    _assert_names(message, path, name, name, ["[study]", "[loads]", "[bearings]", "[simulation]"])
    assert "unknown table" in message
    assert re.search("case-sensitive", message)
