"""The NREL 5MW bolted example (docs/guide/connected-structures.md): the bearing file
holds the hub and blade root its script derives from the published sources (no build, no run)."""
import importlib.util
import math
from pathlib import Path

import pytest

from slewing_model import load_bearing

ROOT = Path(__file__).resolve().parents[1]


def _script():
    spec = importlib.util.spec_from_file_location("nrel5mw_bolted", ROOT / "examples" / "nrel5mw_bolted.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_bearing_file_holds_the_derived_hub_and_blade_root():
    m = _script()
    plain = load_bearing(m.PLAIN)
    d = m.derive(plain)
    m.check_file(d)                                    # raises when the file and the derivation differ
    assert d["root_wall_at_root_m"] == pytest.approx(0.0517 + 2 * 0.00282)
    assert d["root_wall_mean_m"] == pytest.approx(0.05348, abs=1e-5)
    assert d["scale"] == pytest.approx(4.336 / (3.542 - d["root_wall_mean_m"]))
    assert d["hub_wall_mass_equivalent_m"] == pytest.approx(56_780 / (7200 * math.pi * 9.0))
    bolted = load_bearing(m.BOLTED)
    root, hub = bolted.connection["inner"], bolted.connection["outer"]
    assert (root.kind, hub.kind) == ("tube", "tube")
    face = plain.inner_section                         # the root's laminate centred on the inner ring's face
    assert (root.inner_radius + root.outer_radius) / 2 == pytest.approx((face.inner_radius + face.outer_radius) / 2,
                                                                        abs=1e-4)
    assert hub.inner_radius == pytest.approx(plain.outer_section.inner_radius)
    assert bolted.with_connection(None).name == bolted.name          # the same bearing otherwise
    for key in ("pitch_diameter", "ball_count", "ball_diameter", "preload"):
        assert getattr(bolted, key) == getattr(plain, key)


def test_nrel5mw_study_runs_the_bearing_as_it_is_bolted():
    """The NREL 5MW study's default bearing is the bolted one: every case runs flexible
    rings on the bearing file that holds the hub and blade root, the rings' support left to them."""
    from slewing_model.study import load_study

    m = _script()
    study = load_study(ROOT / "examples" / "studies" / "nrel5mw_pitch.toml")
    cases = study.cases()
    assert len(cases) == 10                              # FAST v8 blade 1 + 3 OC3-Hywind runs x 3 blades
    assert study.simulation["bc"] == "free"              # the tubes hold the rings, as the script's bolted case
    for case in cases:
        assert Path(case.variant["file"]).resolve() == m.BOLTED.resolve()
        assert case.variant["ring_model"] == "flexible"
        bearing = load_bearing(case.variant["file"])
        assert set(bearing.connection) == {"inner", "outer"}
