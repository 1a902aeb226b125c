"""The turbine loop as a command and as a study: turbine files, ``slewing turbine``, turbine studies on Dask.

The runs are short (4 s of the NREL 5MW above rated, electric pitch drives on rigid-ring pitch bearings):
a two-case study (bearing friction off and on) on an in-process Dask cluster, and the command on the
friction-on case, whose summary must equal the study's row of that case.
"""
from __future__ import annotations

import csv
import json
import math
import sys
from pathlib import Path

import pytest

pytest.importorskip("rosco", reason="the turbine loop needs ROSCO's library (pip install --no-deps rosco==2.10.6)")
pytest.importorskip("distributed", reason="turbine studies run on Dask distributed")

from slewing_model.cli import main  # noqa: E402
from slewing_turbine.study import (TIMESERIES_COLUMNS, TurbineStudyError, column_name,  # noqa: E402
                                   load_turbine_study, run_turbine_study)
from slewing_turbine.turbine_file import TurbineDefinitionError, load_turbine  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "turbines" / "nrel5mw.toml"
EXAMPLE_STUDY = ROOT / "examples" / "studies" / "turbine_nrel5mw.toml"
T_END = 4.0

# above rated from the start: the blades pitch towards feather at once, against their bearings' friction
CASE = f"""[case]
name = "short"
[turbine]
directory = "{ROOT / 'examples' / 'turbines' / 'nrel5mw'}"
[pitch]
drive = "{ROOT / 'examples' / 'drives' / 'pitch_drive.toml'}"
bearing = "{ROOT / 'examples' / 'bearings' / 'pitch_bearing_nrel5mw.toml'}"
ring_model = "rigid"
friction = true
[wind]
kind = "steady"
speed_m_s = 13.0
[simulation]
t_end_s = {T_END}
rotor_speed_init_rpm = 12.1
settle_s = 1.0
"""


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def _refusal(tmp_path, text, *, error=TurbineDefinitionError) -> str:
    path = _write(tmp_path / "turbine.toml", text)
    with pytest.raises(error) as info:
        load_turbine(path)
    message = str(info.value)
    assert str(path) in message, message
    return message


# ---- the turbine file --------------------------------------------------------------------------------

def test_example_turbine_file_reads():
    case = load_turbine(EXAMPLE)
    assert (case.drives, case.ring_model, case.friction, case.ipc) == ("electric", "rigid", True, False)
    assert case.wind == {"kind": "kaimal", "speed_m_s": 13.0, "seed": 1, "turbulence_class": "B"}
    assert case.bearings == [str(ROOT / "examples" / "bearings" / "pitch_bearing_nrel5mw.toml")] * 3
    assert case.discon_overrides == {}
    assert case.settle == 20.0 and case.config().settle == 20.0 and case.emergency_stop is None
    ipc = load_turbine(EXAMPLE, overrides={"controller.ipc": True})
    assert ipc.discon_overrides == {"IPC_ControlMode": 1, "IPC_KI": [1e-8, 0.0]}
    wind = case.wind_series()
    assert wind.time[-1] >= case.t_end and abs(wind.time[1] - case.dt) < 1e-12


@pytest.mark.parametrize("change, words", [
    (("[pitch]", "[pitch]\nfriction_coeff = 0.2"), ["pitch.friction_coeff", "unknown key in table [pitch]",
                                                  "friction_coefficient"]),
    (("[pitch]", "[pitchh]\n[pitch]"), ["unknown table [pitchh]", "[pitch]", "[wind]"]),
    (('kind = "steady"', 'kind = "turbulent"'), ["wind.kind", "'kaimal'", "'eog'"]),
    (("speed_m_s = 13.0", "speed_m_s = 13.0\nseed = 3"), ["wind.seed", "not a key of wind.kind = 'steady'"]),
    ((f"t_end_s = {T_END}", "t_end_s = -1.0"), ["simulation.t_end_s = -1.0", "must be > 0"]),
    (('ring_model = "rigid"', 'ring_model = "elastic"'), ["pitch.ring_model", "'flexible'", "'none'"]),
    (("friction = true", 'friction = "yes"'), ["pitch.friction", "true or false"]),
    (('bearing = "', 'bearing = "missing_'), ["pitch.bearing", "no such file"]),
    (("[pitch]", "[controller]\nipc = true\n[controller.overrides]\nPC_MaxRate = 0.1\n[pitch]"),
     ["controller.overrides.PC_MaxRate", "no parameter 'PC_MaxRate'", "did you mean 'PC_MaxRat'"]),
    (("[pitch]", "[controller]\nipc_ki = [1e-8, 0.0]\n[pitch]"), ["controller.ipc_ki", "only with controller.ipc"]),
    (("[turbine]", '[turbine]\naero = "cp_table"'), ["pitch.ring_model", "turbine.aero = 'bem'"]),
    (("settle_s = 1.0", f"settle_s = {T_END}"), ["simulation.settle_s", "shorter than simulation.t_end_s"]),
    (("settle_s = 1.0", "settle_s = -1.0"), ["simulation.settle_s", "must be >= 0"]),
    (("[pitch]", "[controller]\nemergency_stop_s = 9.0\n[pitch]"),
     ["controller.emergency_stop_s", "before simulation.t_end_s"]),
])
def test_turbine_file_refuses_bad_keys_and_values(tmp_path, change, words):
    old, new = change
    assert old in CASE
    message = _refusal(tmp_path, CASE.replace(old, new, 1))
    for w in words:
        assert w in message, (w, message)


def test_one_drive_file_for_three_blades(tmp_path):
    other = _write(tmp_path / "drive2.toml", (ROOT / "examples" / "drives" / "pitch_drive.toml").read_text())
    drive = ROOT / "examples" / "drives" / "pitch_drive.toml"
    text = CASE.replace(f'drive = "{drive}"', f'drive = ["{drive}", "{drive}", "{other}"]')
    assert "pitch.drive" in _refusal(tmp_path, text)


# ---- the study file ----------------------------------------------------------------------------------

def test_example_study_has_24_distinct_cases():
    study = load_turbine_study(EXAMPLE_STUDY)
    assert len(study.cases) == 24 == len({c.key for c in study.cases})
    assert {(c.case.wind["speed_m_s"], c.case.wind["seed"], c.case.ipc, c.case.friction) for c in study.cases} == {
        (v, s, i, f) for v in (8.0, 13.0, 18.0) for s in (1, 2) for i in (False, True) for f in (False, True)}
    assert all(c.case.t_end == 60.0 and c.case.settle == 20.0 for c in study.cases)
    again = load_turbine_study(EXAMPLE_STUDY)
    assert [c.key for c in again.cases] == [c.key for c in study.cases]   # keys do not depend on the run


def test_study_file_refuses_unknown_axis_and_bad_case(tmp_path):
    base = _write(tmp_path / "turbine.toml", CASE)
    bad_axis = _write(tmp_path / "a.toml", f'[study]\nturbine = "{base}"\n[axes.wind]\nspeeds = [8.0]\n')
    with pytest.raises(TurbineStudyError, match=r"axes\.wind\.speeds.*not a key of the turbine file"):
        load_turbine_study(bad_axis)
    bad_case = _write(tmp_path / "b.toml", f'[study]\nturbine = "{base}"\n[axes.wind]\nspeed_m_s = [8.0, -2.0]\n')
    with pytest.raises(TurbineStudyError, match=r"case speed_m_s=-2.*wind\.speed_m_s = -2\.0: must be >= 0"):
        load_turbine_study(bad_case)


def test_column_names_carry_units():
    assert column_name("motor torque peak [N m]") == "motor_torque_peak_Nm"
    assert column_name("friction torque mean [kN m]") == "friction_torque_mean_kNm"
    assert column_name("overspeed [%]") == "overspeed_pct"
    assert column_name("motor torque RMS / peak limit") == "motor_torque_rms_over_peak_limit"


# ---- runs --------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def study_run(tmp_path_factory):
    """The two-case study (friction off, on) on an in-process Dask cluster, and the command's run of the
    friction-on case."""
    from distributed import Client

    folder = tmp_path_factory.mktemp("turbine_study")
    base = _write(folder / "turbine.toml", CASE)
    study = _write(folder / "study.toml", f'[study]\nname = "two"\nturbine = "{base}"\n'
                                          f'[axes.pitch]\nfriction = [false, true]\n')
    with Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None) as client:
        report = run_turbine_study(study, folder / "out", client=client, progress=False, figures=True)
    single = folder / "single"
    code = main(["turbine", str(base), "-o", str(single), "--quiet"])
    return folder, report, single, code


def _rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_study_writes_its_folder_and_friction_costs_drive_energy(study_run):
    folder, report, _, _ = study_run
    assert report.cases == 2 and not report.failed, report.failed
    rows = {r["friction"]: r for r in _rows(folder / "out" / "summary.csv")}
    off, on = rows["false"], rows["true"]
    for r in (off, on):
        assert r["status"] == "ok"
        record = json.loads((folder / "out" / "cases" / r["case"] / "result.json").read_text())
        assert record["status"] == "ok" and isinstance(record["controller_messages"], list)
        assert record["cpu_s"] > 0.0
        header = (folder / "out" / "cases" / r["case"] / "timeseries.csv").read_text().splitlines()[0]
        assert header.split(",") == list(TIMESERIES_COLUMNS)
    assert float(off["friction_torque_mean_kNm"]) == 0.0 and float(off["friction_torque_peak_kNm"]) == 0.0
    assert float(on["friction_torque_mean_kNm"]) > 1.0                  # kN m, each blade's bearing turning
    assert float(on["friction_energy_kJ"]) > 0.0 == float(off["friction_energy_kJ"])
    assert float(on["drive_energy_kJ"]) > float(off["drive_energy_kJ"])   # the drives pay for the friction
    assert float(on["pitch_travel_deg"]) > 2.0                             # pitching towards feather
    assert float(on["settle_time_s"]) == float(off["settle_time_s"]) == 1.0
    # the pitch oscillations by x/2b, per blade: only where a bearing was stepped (friction on)
    for b in (1, 2, 3):
        assert off[f"x2b_below_1_pct_{b}"] == "" and float(on[f"oscillations_{b}"]) >= 0.5
        shares = float(on[f"x2b_below_1_pct_{b}"]) + float(on[f"x2b_above_1_pct_{b}"])
        assert shares == pytest.approx(100.0)
    assert report.figures and Path(report.figures[0]).is_file()
    assert json.loads((folder / "out" / "study.json").read_text())["name"] == "two"


def test_study_resumes_without_running_finished_cases(study_run):
    folder, report, _, _ = study_run
    again = run_turbine_study(folder / "study.toml", folder / "out", progress=False, figures=False)
    assert sorted(again.skipped) == sorted(r["case"] for r in report.rows) and not again.ran


def test_command_writes_summary_and_figure_equal_to_the_study_row(study_run):
    folder, _, single, code = study_run
    assert code == 0
    assert (single / "turbine.png").stat().st_size > 10_000
    summary = json.loads((single / "summary.json").read_text())
    assert summary["case"]["friction"] is True and summary["summary"]["friction torque mean [kN m]"] > 1.0
    (row,) = _rows(single / "summary.csv")
    (study_row,) = [r for r in _rows(folder / "out" / "summary.csv") if r["friction"] == "true"]
    compared = [k for k in row if k not in ("name", "seconds_per_simulated_second")]
    assert len(compared) > 20
    for k in compared:
        assert math.isclose(float(row[k]), float(study_row[k]), rel_tol=1e-9, abs_tol=1e-12), (k, row[k], study_row[k])
    lines = (single / "timeseries.csv").read_text().splitlines()
    assert len(lines) == 1 + round(T_END / 0.01) + 1


def test_command_refuses_bad_file_in_one_line(tmp_path, capsys):
    path = _write(tmp_path / "turbine.toml", CASE.replace("[pitch]", "[pitch]\nfriction_coeff = 0.2", 1))
    assert main(["turbine", str(path), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("slewing turbine: error: ") and "pitch.friction_coeff" in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_slewing_model_does_not_import_the_turbine_package():
    import subprocess

    code = "import sys, slewing_model, slewing_model.cli, slewing_model.study; print('slewing_turbine' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == "False"


def test_ipc_switch_reaches_the_controller(tmp_path):
    """``controller.ipc = true``: ROSCO's 1P individual pitch control turns each blade its own way (the sheared
    wind's and gravity's 1P root moments); off, the three demands are equal (ideal drives: seconds)."""
    import numpy as np

    path = _write(tmp_path / "turbine.toml", CASE.replace('[pitch]', '[pitch]\ndrives = "ideal"', 1)
                  .replace(f"t_end_s = {T_END}", "t_end_s = 5.0"))
    spread = {}
    for ipc in (False, True):
        result = load_turbine(path, overrides={"controller.ipc": ipc}).run()
        spread[ipc] = float(np.degrees(np.max(np.ptp(result.pitch_demand, axis=1))))
    assert spread[False] == 0.0 and spread[True] > 0.1, spread


def test_command_without_rosco_says_how_to_install_it(tmp_path, monkeypatch, capsys):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "rosco" else real(name, *a))
    assert main(["turbine", str(EXAMPLE), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "pip install --no-deps rosco==2.10.6" in err and not (tmp_path / "out").exists()
