"""Studies (`slewing batch`, slewing_model.study): definition, per-case numbers, the Dask engine.

Small cases (table3, rigid rings, a few dozen steps) so that the Dask runs, each with
its own LocalCluster of worker processes, stay within seconds.
"""
import csv
import json
import os
import signal
from pathlib import Path

import numpy as np
import pytest

from slewing_model import Loads, load_bearing, solve
from slewing_model.friction import friction_torque
from slewing_model.study import StudyDefinitionError, load_study, run_case, run_study
from slewing_model.study.case import TIMESERIES_COLUMNS
from slewing_model.study.engine import _Prepared

distributed = pytest.importorskip("distributed", reason="the study engine needs dask[distributed] (extra 'study')")

ROOT = Path(__file__).resolve().parents[1]
TABLE3 = ROOT / "examples" / "bearings" / "table3.toml"
OPENFAST = ROOT.parent / "shared" / "data" / "openfast"

SYNTHETIC = """
[bearings.synthetic_errors]
waviness_orders = [2, 3, 4, 5]
radial_amplitude_um = [3.0, 2.0, 1.5, 1.0]
axial_amplitude_um = [2.0, 1.5, 1.0, 0.75]
ball_tolerance_um = 2.0
"""


def idling(name, steps, fz=0.0, omega=0.1):
    return (f'[[loads]]\nname = "{name}"\nconstant = [0, 0, {fz!r}, 0, 0, 0]\nomega_rad_s = {omega!r}\n'
            f"duration_s = {0.02 * (steps - 1)!r}\nsteps = {steps}\n")


def write_study(folder, loads, preloads=(0, 20), seeds=(1, 2), extra_loads=""):
    text = (f'[study]\nname = "test"\n\n{loads}{extra_loads}\n[bearings]\nfiles = ["{TABLE3.as_posix()}"]\n'
            f'ring_model = ["rigid"]\npreload_um = {list(preloads)}\nerror_seeds = {list(seeds)}\n{SYNTHETIC}')
    path = Path(folder) / "study.toml"
    path.write_text(text)
    return path


def summary(path):
    with open(Path(path) / "summary.csv", newline="") as fh:
        return list(csv.DictReader(fh))


# ---- the study file ---------------------------------------------------------------------------

@pytest.mark.parametrize("change, key, rule", [
    (('ring_model = ["rigid"]', 'ring_model = ["elastic"]'), "bearings.ring_model", "'rigid' or 'flexible'"),
    (("preload_um = [0, 20]", 'preload_um = ["a lot"]'), "bearings.preload_um", "finite number"),
    (("error_seeds = [1, 2]", "error_seeds = [1, 1]"), "bearings.error_seeds", "distinct"),
    (("steps = 5", "steps = 1"), "loads[0].steps", ">= 2"),
    (('name = "test"', 'name = "test"\nworkers = 4'), "study.workers", "unknown key"),
    (("constant = [0, 0, 0.0, 0, 0, 0]", "constant = [0, 0, 0]"), "loads[0].constant", "six finite numbers"),
])
def test_study_file_error_names_key_value_and_rule(tmp_path, change, key, rule):
    path = write_study(tmp_path, idling("idle", 5))
    path.write_text(path.read_text().replace(*change))
    with pytest.raises(StudyDefinitionError) as info:
        load_study(path)
    assert key in str(info.value) and rule in str(info.value)


def test_cases_are_the_product_and_keys_follow_content_not_place(tmp_path):
    loads = tmp_path / "a" / "loads.csv"
    loads.parent.mkdir()
    loads.write_text("time,Fx,Fy,Fz,Mx,My\n0,0,0,1e4,0,0\n1,0,0,2e4,0,0\n")
    entry = f'[[loads]]\ncsv = "{loads.as_posix()}"\n'
    study = load_study(write_study(tmp_path / "a", entry + idling("idle", 5), seeds=(1, 2, 3)))
    cases = study.cases()
    assert len(cases) == 2 * 2 * 3                                   # loads x preloads x seeds
    assert len({c.key for c in cases}) == len(cases)
    # the same study somewhere else, its load file copied: same keys
    other = tmp_path / "b" / "loads.csv"
    other.parent.mkdir()
    other.write_bytes(loads.read_bytes())
    moved = load_study(write_study(tmp_path / "b", f'[[loads]]\ncsv = "{other.as_posix()}"\n' + idling("idle", 5),
                                   seeds=(1, 2, 3)))
    assert [c.key for c in moved.cases()] == [c.key for c in cases]
    # one value of the load file changed: that series' cases get new keys, the others keep theirs
    other.write_text(loads.read_text().replace("2e4", "2.5e4"))
    changed = [c.key for c in moved.cases()]
    assert [a != b for a, b in zip(changed, (c.key for c in cases))] == [True] * 6 + [False] * 6


def test_old_and_new_csv_headers_read_with_motion(tmp_path):
    from slewing_model.study.series import read_csv

    old = tmp_path / "old.csv"
    old.write_text("time,Fx,Fy,Fz,Mx,My\n0,1,2,3,4,5\n2,1,2,3,4,5\n")
    s = read_csv(str(old), omega_default=0.5)
    np.testing.assert_allclose(s.psi, [0.0, 1.0])                     # psi = omega t
    new = tmp_path / "new.csv"
    new.write_text("# load_frame = rotating\ntime,Fx,Fy,Fz,Mx,My,Mz,psi,omega\n0,1,2,3,4,5,6,0.1,0.01\n"
                   "1,1,2,3,4,5,6,0.2,0.02\n")
    s = read_csv(str(new))
    assert s.load_frame == "rotating"
    np.testing.assert_array_equal(s.loads[:, 5], [6, 6])
    np.testing.assert_array_equal(s.omega, [0.01, 0.02])
    with pytest.raises(ValueError, match="load_frame = 'fixed' in the study"):
        read_csv(str(new), load_frame="fixed")


# ---- one case ------------------------------------------------------------------------------------

def test_case_statistics_agree_with_independent_computation(tmp_path):
    """Rigid rings, preload 20 um, a load ramp while the ring turns unevenly: each step's ball load
    against a cold `solve`, the torque against `friction_torque`; the statistics against numpy's
    trapezoid rule; the load spectrum adds up to the duration and the rotation for every ball."""
    t = np.linspace(0.0, 1.0, 21)
    psi = 0.3 * t ** 2
    series = tmp_path / "ramp.csv"
    rows = [[tk, 1e3 * tk, 0.0, 2e4 + 3e4 * tk, 0.0, 2e3 * tk, 0.0, pk, 0.6 * tk] for tk, pk in zip(t, psi)]
    np.savetxt(series, rows, delimiter=",", header="time,Fx,Fy,Fz,Mx,My,Mz,psi,omega", comments="", fmt="%.17g")
    study = load_study(write_study(tmp_path, f'[[loads]]\ncsv = "{series.as_posix()}"\n', preloads=(20,),
                                   seeds=(7,)).as_posix())
    (case,) = study.cases()
    result = run_case(_Prepared(study.simulation).task(case))
    assert result.status == "ok"
    out = {c: result.timeseries[:, j] for j, c in enumerate(TIMESERIES_COLUMNS)}

    from slewing_model.study.case import case_bearing
    bearing = case_bearing(load_bearing(TABLE3), case.variant).with_preload(20e-6)
    for k in (0, 10, 20):
        cold = solve(bearing, Loads(*rows[k][1:6]), psi=psi[k])
        assert out["max_ball_load"][k] == pytest.approx(cold.max_ball_load, rel=1e-7)
        assert out["friction_torque_magnitude"][k] == pytest.approx(
            friction_torque(bearing, cold, mu=0.1, omega=1.0).magnitude, rel=2e-3)
    s = result.statistics
    trapezoid = getattr(np, "trapezoid", None) or np.trapz
    torque = out["friction_torque_magnitude"]
    assert s["friction_torque_mean"] == pytest.approx(trapezoid(torque, t) / 1.0, rel=1e-12)
    assert s["friction_energy"] == pytest.approx(trapezoid(torque * 0.6 * t, t), rel=1e-12)
    assert s["friction_torque_max"] == torque.max()
    assert s["max_ball_load"] == out["max_ball_load"].max()
    assert s["min_static_safety_factor"] == out["static_safety_factor"].min()
    hist = result.histogram
    for ball in (1, 30, 67):
        for diagonal in (13, 24):
            rows_b = hist[(hist[:, 0] == ball) & (hist[:, 1] == diagonal)]
            assert rows_b[:, 4].sum() == pytest.approx(1.0, rel=1e-12)        # s, the duration
            assert rows_b[:, 5].sum() == pytest.approx(0.3, rel=1e-12)        # rad, integral of omega
    assert hist[:, 3].max() >= s["max_ball_load"]


# ---- the Dask engine ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def cluster():
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}) as c:
        yield c


def test_one_and_two_workers_give_identical_results(tmp_path):
    path = write_study(tmp_path, idling("idle", 15) + idling("axial", 15, fz=3e4))
    one = run_study(path, tmp_path / "one", workers=1, progress=False, figures=False)
    two = run_study(path, tmp_path / "two", workers=2, progress=False, figures=False)
    assert len(one.ran) == len(two.ran) == 8 and not one.failed and not two.failed
    assert len({r["worker"] for r in two.rows}) == 2                  # both workers took cases
    for a, b in zip(one.rows, two.rows):
        assert {k: v for k, v in a.items() if k not in ("elapsed_s", "worker")} == \
               {k: v for k, v in b.items() if k not in ("elapsed_s", "worker")}
        for name in ("timeseries.csv", "ball_load_histogram.csv"):
            assert (tmp_path / "one" / "cases" / a["case"] / name).read_bytes() == \
                   (tmp_path / "two" / "cases" / b["case"] / name).read_bytes()


def test_bad_cases_are_reported_and_the_others_finish(tmp_path, capsys):
    from slewing_model.cli import main

    garbled = tmp_path / "garbled.csv"
    garbled.write_text("time,Fx,Fy,Fz,Mx,My\n0,0,0,1e4,0,0\n1,0,0,lots,0,0\n")
    extra = f'[[loads]]\ncsv = "{garbled.as_posix()}"\n' + idling("crushing", 5, fz=5e8)
    path = write_study(tmp_path, idling("idle", 5), seeds=(1,), extra_loads=extra)
    code = main(["batch", str(path), "-o", str(tmp_path / "out"), "--workers", "2", "--quiet"])
    assert code == 1
    rows = {(r["load"], r["preload_um"]): r for r in summary(tmp_path / "out")}
    assert len(rows) == 3 * 2
    for preload in ("0.0", "20.0"):
        assert rows[("idle", preload)]["status"] == "ok"
        assert "line 3, column Fz = 'lots'" in rows[("garbled", preload)]["status"]
        assert rows[("crushing", preload)]["status"].startswith("LoadCapacityError at t = 0 s")
        assert rows[("crushing", preload)]["friction_torque_max"] == ""
    assert all("\n" not in r["status"] for r in rows.values())
    printed = capsys.readouterr()
    assert "4 failed" in printed.out
    # each failure names the study file and the case
    assert f"{path}: case " in printed.err and "(garbled | table3" in printed.err


def test_rerun_skips_finished_cases(tmp_path, cluster):
    path = write_study(tmp_path, idling("idle", 8), seeds=(1, 2))
    out = tmp_path / "out"
    first = run_study(path, out, scheduler=cluster.scheduler_address, progress=False, figures=False)
    assert len(first.ran) == 4 and not first.skipped and not first.failed
    stamps = {k: os.stat(out / "cases" / k / "result.json").st_mtime_ns for k in first.ran}
    again = run_study(path, out, scheduler=cluster.scheduler_address, progress=False, figures=False)
    assert again.ran == [] and sorted(again.skipped) == sorted(first.ran)
    assert again.rows == first.rows
    assert {k: os.stat(out / "cases" / k / "result.json").st_mtime_ns for k in first.ran} == stamps
    # one more preload: only its two cases run
    path.write_text(path.read_text().replace("preload_um = [0, 20]", "preload_um = [0, 20, 40]"))
    grown = run_study(path, out, scheduler=cluster.scheduler_address, progress=False, figures=False)
    assert len(grown.ran) == 2 and sorted(grown.skipped) == sorted(first.ran)
    assert {r["preload_um"] for r in grown.rows if r["case"] in grown.ran} == {"40.0"}


def test_killed_worker_cases_complete(tmp_path):
    """A worker process is killed (SIGKILL) while it runs a case: Dask reschedules its cases on the
    other worker and the restarted one; every case finishes, with the numbers of an undisturbed run."""
    from distributed import Client, LocalCluster

    path = write_study(tmp_path, idling("idle", 200, omega=0.05), preloads=(20, 30), seeds=(1, 2, 3, 4))
    killed = {}

    def kill_a_busy_worker(case, record, client):
        if killed:
            return
        busy = {w: keys for w, keys in client.processing().items() if keys}
        if not busy:
            return
        worker, keys = next(iter(busy.items()))
        pid = client.run(os.getpid, workers=[worker])[worker]
        os.kill(pid, signal.SIGKILL)
        killed.update(worker=worker, keys=[k.removeprefix("slewing-case-") for k in keys], pid=pid)

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                      scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}) as cluster, \
            Client(cluster) as client:
        report = run_study(path, tmp_path / "out", client=client, progress=False, figures=False,
                           on_result=kill_a_busy_worker)
    assert killed, "no worker was busy to be killed"
    assert len(report.ran) == 8 and not report.failed
    rows = {r["case"]: r for r in report.rows}
    study = load_study(path)
    for case in study.cases():
        if case.key in killed["keys"]:
            assert rows[case.key]["status"] == "ok"
            assert not rows[case.key]["worker"].endswith(f":{killed['pid']}")
            undisturbed = run_case(_Prepared(study.simulation).task(case))
            recorded = json.loads((tmp_path / "out" / "cases" / case.key / "result.json").read_text())
            assert recorded["statistics"] == undisturbed.statistics


@pytest.mark.skipif(not OPENFAST.is_dir(), reason=f"{OPENFAST} (real OpenFAST files) is absent")
def test_openfast_pitch_case_steps_the_recorded_pitch_angle(tmp_path, cluster):
    pytest.importorskip("slewing_model.loads.aeroelastic", reason="the OpenFAST channel mapping is not there yet")
    fast = OPENFAST / "NREL5MW_Land_FASTv8_CertTest18_turb12mps_60s.outb"
    text = (f'[[loads]]\nopenfast = "{fast.as_posix()}"\nbearing = "pitch"\nblades = [1]\nt_start_s = 30.0\n'
            f't_end_s = 31.0\nevery = 4\n\n[bearings]\nfiles = ["{(ROOT / "examples/bearings/pitch_bearing.toml").as_posix()}"]\n')
    path = tmp_path / "fast.toml"
    path.write_text(text)
    report = run_study(path, tmp_path / "out", scheduler=cluster.scheduler_address, progress=False, figures=False)
    (row,) = report.rows
    assert row["status"] == "ok"
    ts = np.loadtxt(tmp_path / "out" / "cases" / row["case"] / "timeseries.csv", delimiter=",", skiprows=1)
    assert ts[0, 0] == pytest.approx(30.0, abs=0.01) and ts[-1, 0] == pytest.approx(31.0, abs=0.03)
    assert ts.shape[0] == pytest.approx(1.0 / 0.00625 / 4, abs=2)
    pitch = -np.degrees(ts[:, 1])                    # psi = -BldPitch1 (mounting "tip", slewing_model.loads.aeroelastic)
    assert np.all((pitch > -0.1) & (pitch < 8.0)) and np.ptp(pitch) > 0.01          # BldPitch1: -0.02..7.85 deg
    assert float(row["min_static_safety_factor"]) > 1.0


def test_superelement_built_once_per_bearing_variant(tmp_path):
    """Flexible rings: the cases of one bearing file (here 2 preloads x 2 seeds x 2 load series) carry
    one and the same superelement, built before submission; the rigid cases carry none."""
    path = write_study(tmp_path, idling("idle", 5) + idling("axial", 5, fz=1e4))
    path.write_text(path.read_text().replace('ring_model = ["rigid"]', 'ring_model = ["rigid", "flexible"]'))
    study = load_study(path)
    prepared = _Prepared(study.simulation)
    tasks = [prepared.task(c) for c in study.cases()]
    flexible = [t.superelement for t in tasks if t.variant["ring_model"] == "flexible"]
    assert len(flexible) == 8 and all(se is flexible[0] for se in flexible)
    assert all(t.superelement is None for t in tasks if t.variant["ring_model"] == "rigid")
    flexible[0].check(load_bearing(TABLE3))              # built for this bearing


# ---- the files a study names are checked before anything runs ---------------------------------------

def test_missing_bearing_file_is_refused_up_front_with_one_message(tmp_path, capsys):
    """Before: each of the study's cases failed with the same ValueError (8 lines), exit 1, and
    the output folder was left behind. Now: one message naming the key and the file, exit 2
    (a bad study), and nothing written."""
    from slewing_model.cli import main

    absent = tmp_path / "no_such_bearing.toml"
    path = write_study(tmp_path, idling("idle", 5) + idling("axial", 5, fz=3e4), seeds=(1, 2))
    path.write_text(path.read_text().replace(f'files = ["{TABLE3.as_posix()}"]',
                                             f'files = ["{TABLE3.as_posix()}", "{absent.as_posix()}"]'))
    assert len(load_study(path).cases()) == 2 * 2 * 2 * 2                # loads x files x preloads x seeds
    out_dir = tmp_path / "out"
    assert main(["batch", str(path), "-o", str(out_dir), "--workers", "1", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.count("no_such_bearing.toml") == 1, err
    assert f"bearings.files = '{absent}'" in err and "No such file or directory" in err
    assert not out_dir.exists()


def test_every_bad_file_of_a_study_is_named_in_one_message(tmp_path, capsys):
    from slewing_model.cli import main

    broken = tmp_path / "broken.toml"
    broken.write_text(TABLE3.read_text().replace("ball_count = ", "ball_count = -"))
    absent_loads = tmp_path / "absent.csv"
    path = write_study(tmp_path, f'[[loads]]\ncsv = "{absent_loads.as_posix()}"\n' + idling("idle", 5), seeds=(1,))
    path.write_text(path.read_text().replace(f'files = ["{TABLE3.as_posix()}"]', f'files = ["{broken.as_posix()}"]'))
    out_dir = tmp_path / "out"
    out_dir.mkdir()                                                      # an existing folder stays untouched
    assert main(["batch", str(path), "-o", str(out_dir), "--workers", "1", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "2 files cannot be used" in err
    assert f"loads.csv = '{absent_loads}': cannot read the load series: No such file or directory" in err
    assert f"{broken}: bearing.ball_count = -" in err                  # the bearing file's own message
    assert list(out_dir.iterdir()) == []


def test_every_json_of_a_study_is_strict_json_and_no_track_0(tmp_path):
    """A ring standing still (no cycles: infinite lives, no worst track, no DG03 ratio) and one turning:
    every JSON file the study writes parses as RFC 8259 JSON (no bare Infinity or NaN, which e.g.
    Node's JSON.parse refuses); summary.csv has no track 0 and no "nan" for the still case."""
    path = write_study(tmp_path, idling("still", 6, fz=3e4, omega=0.0) + idling("turning", 6, fz=3e4),
                       preloads=(0,), seeds=(1,))
    run_study(path, tmp_path / "out", workers=1, progress=False, figures=True)

    def refuse(name):
        raise ValueError(f"{name} is not JSON")

    files = list((tmp_path / "out").rglob("*.json"))
    assert len(files) >= 5                      # study.json, and per case case.json, result.json, life_summary.json
    for f in files:
        json.loads(f.read_text(), parse_constant=refuse)
    rows = {r["load"]: r for r in summary(tmp_path / "out")}
    still = rows["still"]
    assert still["life_worst_track"] == "" and still["life_L10_h"] == "inf" and still["life_dg03_ratio"] == ""
    assert "nan" not in " ".join(still.values()).lower()
    assert rows["turning"]["life_worst_track"] in ("1", "2", "3", "4")


def test_life_figure_groups_variants_and_adds_only_parts_of_one_duty(tmp_path):
    """Two load series (parts of one duty) x two preloads (alternative designs): the life figure's groups
    are the two bearing variants, each holding both load series; the variants are never added."""
    from slewing_model.study.figures import life_groups

    path = write_study(tmp_path, idling("a", 6, fz=3e4) + idling("b", 6, fz=5e4), preloads=(0, 20), seeds=(1,))
    result = run_study(path, tmp_path / "out", workers=1, progress=False, figures=True)
    groups = life_groups(str(tmp_path / "out"), result.rows)
    assert len(groups) == 2
    for folders in groups.values():
        loads = sorted(r["load"] for r in result.rows if os.path.join(str(tmp_path / "out"), "cases", r["case"]) in folders)
        assert loads == ["a", "b"]
    assert (tmp_path / "out" / "figures" / "life.png").stat().st_size > 0
