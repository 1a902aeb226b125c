"""``slewing life LOADS.csv BEARING.toml``: runs a series and writes its table, maps and figure."""
import json
from pathlib import Path

import numpy as np

from slewing_model.cli import main

ROOT = Path(__file__).resolve().parents[1]


def test_life_command_writes_table_and_figure(tmp_path, capsys):
    """A steady swing of 10° (above the critical angle) under an axial load: five rainflow cycles
    (four full and two halves: 0 -> 10° -> 0 five times), worst track on diagonal 1 (Fz > 0 loads
    contacts 1 and 3, DESIGN.md), and the files."""
    t = np.linspace(0.0, 10.0, 401)
    psi = np.radians(5.0) * (1 - np.cos(2 * np.pi * t / 2.0))      # 0 .. 10 deg, 5 periods
    loads = np.column_stack([t, 0 * t, 0 * t, np.full_like(t, 5e4), 0 * t, 0 * t, 0 * t, psi])
    csv = tmp_path / "loads.csv"
    np.savetxt(csv, loads, delimiter=",", header="time,Fx,Fy,Fz,Mx,My,Mz,psi", comments="")
    out = tmp_path / "out"
    assert main(["life", str(csv), str(ROOT / "examples/bearings/table3.toml"), "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "L10 (DG03" in text and "x/2b < 1" in text
    summary = json.loads((out / "life_summary.json").read_text())
    assert summary["life_cycles"] == 5.0
    assert summary["life_worst_track"] in (1, 3)
    assert summary["life_L10_h"] > 0 and summary["life_map_L10_h"] > 0
    for name in ("raceway_damage.csv", "life_cycles.csv", "life.png"):
        assert (out / name).stat().st_size > 0


def test_parquet_time_series_round_trip(tmp_path):
    """A case's time series written as Parquet reads back bit for bit (CSV keeps 10 digits)."""
    pq = __import__("pytest").importorskip("pyarrow.parquet")
    from slewing_model.study.case import TIMESERIES_COLUMNS
    from slewing_model.study.engine import write_parquet

    table = np.random.default_rng(3).normal(size=(50, len(TIMESERIES_COLUMNS)))
    assert write_parquet(str(tmp_path / "t.parquet"), table, TIMESERIES_COLUMNS)
    back = pq.read_table(tmp_path / "t.parquet")
    assert back.column_names == list(TIMESERIES_COLUMNS)
    np.testing.assert_array_equal(np.column_stack([back.column(c).to_numpy() for c in TIMESERIES_COLUMNS]), table)
