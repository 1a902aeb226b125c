"""Figures a user reads at a glance: what each figure states, and that the study
figures draw what a study gives (idling without a drive moment, thousands of cases)."""
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("matplotlib")

from slewing_model.study import load_study                       # noqa: E402
from slewing_model.study.case import TIMESERIES_COLUMNS          # noqa: E402
from slewing_model.study.figures import errors_note, overview, psi_note, time_series  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def test_monte_carlo_figure_states_its_error_amplitudes():
    # the amplitudes written in the study file, examples/studies/table3_tolerance_monte_carlo.toml
    note = errors_note(load_study(ROOT / "examples/studies/table3_tolerance_monte_carlo.toml").cases())
    assert "radial 3/2/1.5/1 um" in note and "axial 2/1.5/1/0.75 um" in note
    assert "+-2 um" in note and "200 seeds" in note


def test_psi_note_explains_the_sign_of_the_pitch_angle():
    # docs/guide/openfast-loads.md: a pitch bearing mounted 'tip' (+z to the tip) turns by -BldPitch
    assert "-BldPitch" in psi_note({"kind": "openfast", "bearing": "pitch"})
    assert "+BldPitch" in psi_note({"kind": "openfast", "bearing": "pitch", "mounting": "hub"})
    assert psi_note({"kind": "constant"}) == ""


def _timeseries(tmp_path, mz):
    n = 20
    data = np.zeros((n, len(TIMESERIES_COLUMNS)))
    col = {k: j for j, k in enumerate(TIMESERIES_COLUMNS)}
    data[:, col["time"]] = np.arange(n)
    data[:, col["psi"]] = 0.01 * np.arange(n)
    data[:, col["Mz"]] = mz
    data[:, col["friction_torque_magnitude"]] = 1000.0 + np.sin(np.arange(n))
    data[:, col["max_ball_load"]] = 5000.0
    path = tmp_path / "timeseries.csv"
    np.savetxt(path, data, delimiter=",", header=",".join(TIMESERIES_COLUMNS), comments="")
    return path


def _axes_of(monkeypatch, draw):
    """The axes of the figure ``draw()`` saves (counted before it is closed)."""
    import matplotlib.figure

    seen = []
    original = matplotlib.figure.Figure.savefig

    def spy(fig, *a, **k):
        seen.append(fig)
        return original(fig, *a, **k)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", spy)
    draw()
    return seen[-1].axes


def test_worst_case_has_no_empty_drive_moment_axis_when_idling(tmp_path, monkeypatch):
    idle = _axes_of(monkeypatch, lambda: time_series(str(tmp_path / "a.png"), _timeseries(tmp_path, 0.0), "idle"))
    driven = _axes_of(monkeypatch, lambda: time_series(str(tmp_path / "b.png"), _timeseries(tmp_path, 5e4), "driven"))
    assert len(idle) == 3 and len(driven) == 4          # the drive moment's twin axis only where there is one
    assert idle[1].get_ylim()[0] == 0.0                 # friction torque from zero: the ripple at its true size


def test_overview_of_many_cases_keeps_the_groups_apart(tmp_path, monkeypatch):
    rows = []
    for model in ("rigid", "flexible"):
        for preload in (0.0, 20.0, 40.0):
            for seed in range(20):
                value = (1 + preload) * (2 if model == "rigid" else 1) * (1 + 0.01 * seed)
                rows.append({"status": "ok", "name": f"idle | table3, {model}", "ring_model": model,
                             "preload_um": str(preload), "friction_coefficient": "0.1", "bearing": "table3.toml",
                             "load": "idle", "friction_torque_mean": str(value), "friction_torque_p99": str(value),
                             "friction_torque_max": str(value), "max_ball_load": str(100 * value),
                             "min_static_safety_factor": str(100 / value), "friction_energy": str(10 * value)})
    axes = _axes_of(monkeypatch, lambda: overview(str(tmp_path / "o.png"), rows))
    labels = [t.get_text() for t in axes[0].get_yticklabels()]
    assert labels == [f"{m}, {p:g} um" for m in ("rigid", "flexible") for p in (0, 20, 40)]   # not pooled
