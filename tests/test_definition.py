"""Bearing definition files: every rejection rule names the key, the value and the rule."""
import copy
import math
import tomllib

import numpy as np
import pytest

from slewing_model import BearingDefinitionError, bearing_from_dict, load_bearing
from slewing_model.bearing.geometry import Bearing

GOOD = {
    "bearing": {"name": "t", "pitch_diameter_mm": 541.0, "ball_diameter_mm": 25.0, "groove_radius_mm": 13.25,
                "contact_angle_deg": 45.0, "ball_count": 67, "preload_um": 0.0},
    "material": {"youngs_modulus_gpa": 200.0, "poisson_ratio": 0.3},
}


def _with(table, key, value):
    d = copy.deepcopy(GOOD)
    d.setdefault(table, {})
    if value is _DELETE:
        del d[table][key]
    else:
        d[table][key] = value
    return d


_DELETE = object()


def test_table1_is_the_paper_bearing():
    b = load_bearing("examples/bearings/table1.toml")
    assert (b.pitch_diameter, b.ball_diameter, b.ball_count) == (1.5, 0.035, 100)
    assert np.allclose(b.groove_radius, 0.01856) and b.contact_angle == pytest.approx(math.radians(45))


def test_groove_centres_lie_on_the_contact_line():
    # DESIGN.md: on the contact line, far side of the ball centre, at Rc - Dw/2 from it
    b = bearing_from_dict(GOOD)
    centre = np.array([b.pitch_diameter / 2, 0.0])
    for i in range(4):
        v = b.groove_centres[i] - centre
        assert np.linalg.norm(v) == pytest.approx(b.groove_radius[i] - b.ball_diameter / 2)
        assert np.allclose(v / np.linalg.norm(v), -b.contact_normals[i])
    # contact 1 is upper-outer: its contact point is above and outside the ball centre
    assert np.all(b.contact_normals[0] > 0)


def test_four_groove_radii_may_be_given():
    b = bearing_from_dict(_with("bearing", "groove_radius_mm", [13.0, 13.25, 13.5, 13.75]))
    assert np.allclose(b.groove_radius * 1e3, [13.0, 13.25, 13.5, 13.75])


@pytest.mark.parametrize("table,key,value,rule", [
    ("bearing", "pitch_diameter_mm", _DELETE, "missing key"),
    ("bearing", "ball_diameter_mm", _DELETE, "missing key"),
    ("bearing", "groove_radius_mm", _DELETE, "missing key"),
    ("bearing", "contact_angle_deg", _DELETE, "missing key"),
    ("bearing", "ball_count", _DELETE, "missing key"),
    ("bearing", "pitch_diameter_mm", float("nan"), "must be a finite number"),
    ("bearing", "ball_diameter_mm", float("inf"), "must be a finite number"),
    ("bearing", "ball_diameter_mm", -25.0, "must be > 0"),
    ("bearing", "pitch_diameter_mm", 0.0, "must be > 0"),
    ("bearing", "groove_radius_mm", -13.0, "must be > 0"),
    ("bearing", "groove_radius_mm", 12.0, r"osculation s = Dw/\(2 Rc\) = 1.0417 for contact 1 must lie in \(0, 1\)"),
    ("bearing", "groove_radius_mm", [13.25, 13.25, 12.5, 13.25], "for contact 3 must lie in"),
    ("bearing", "groove_radius_mm", [13.25, 13.25], "one number or a list of four"),
    ("bearing", "groove_radius_mm", "13", "must be a number"),
    ("bearing", "contact_angle_deg", 90.0, r"must lie in \(0, 90\)"),
    ("bearing", "contact_angle_deg", 0.0, r"must lie in \(0, 90\)"),
    ("bearing", "ball_count", 68, "do not fit the pitch circumference"),
    ("bearing", "ball_count", 12.5, "must be a whole number"),
    ("bearing", "ball_count", 2, "at least 3"),
    ("bearing", "preload_um", 3000.0, "10 % of the ball diameter"),
    ("bearing", "preload_um", float("nan"), "must be a finite number"),
    ("bearing", "moving_ring", "middle", "must be 'inner' or 'outer'"),
    ("bearing", "pitch_diam_mm", 541.0, "unknown key"),
    ("material", "poisson_ratio", 0.5, r"must lie in \(0, 0.5\)"),
    ("material", "youngs_modulus_gpa", -200.0, "must be > 0"),
    ("rings", "gap_mm", 20.0, "smaller than half the ball diameter"),
    ("rings", "outer_ring_outer_diameter_mm", 560.0, "so the groove fits"),
    ("rings", "inner_ring_bore_diameter_mm", 500.0, "so the groove fits"),
    ("rings", "outer_ring_height_mm", 20.0, "must exceed the ball diameter"),
    ("rings", "outer_ring_height_mm", 26.0, "beyond half the ring height"),
    ("rings", "inner_ring_bolted_face", "side", "must be 'lower' or 'upper'"),
])
def test_bad_value_is_refused_naming_key_value_and_rule(table, key, value, rule):
    with pytest.raises(BearingDefinitionError) as info:
        bearing_from_dict(_with(table, key, value))
    message = str(info.value)
    if value is _DELETE:     # TOML has no null: the message names the table and the absent key
        assert message.startswith(f"[{table}]: ") and f"missing key `{key}`" in message, message
    else:
        assert message.startswith(f"{table}.{key}") or message.startswith(f"{table}.") and key in message
    assert rule.replace("\\", "") in message or __import__("re").search(rule, message)
    if value is not _DELETE and not isinstance(value, list):
        assert _spelt_value(message) == value or math.isnan(value) and math.isnan(_spelt_value(message))


def _spelt_value(message):
    """The value a message ``key = value: rule`` quotes, read back as TOML (fails on a Python spelling
    such as True, None or 'text' with a quote inside)."""
    assert " = " in message, message
    spelt = message.split(" = ", 1)[1]
    for end in range(len(spelt), 0, -1):      # the longest prefix that is a TOML value followed by ": "
        if spelt[end:].startswith(": "):
            try:
                return tomllib.loads(f"v = {spelt[:end]}")["v"]
            except tomllib.TOMLDecodeError:
                continue
    raise AssertionError(f"no TOML value in {message!r}")


@pytest.mark.parametrize("table,key,value", [
    ("bearing", "ball_count", True),
    ("bearing", "pitch_diameter_mm", False),
    ("bearing", "moving_ring", True),
    ("bearing", "groove_radius_mm", [13.25, True]),
    ("bearing", "ball_diameter_mm", {"value": 25.0, "unit": "mm"}),
    ("bearing", "moving_ring", "it's \"inner\""),
    ("rings", "inner_ring_bolted_face", ["lower"]),
    ("material", "poisson_ratio", float("inf")),
])
def test_refused_value_is_quoted_as_toml(table, key, value):
    # the value in the message reads back (as TOML) to what the file held: true, not True
    with pytest.raises(BearingDefinitionError) as info:
        bearing_from_dict(_with(table, key, value))
    assert _spelt_value(str(info.value)) == value, str(info.value)


def test_misspelt_subtable_is_named_as_a_table(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(BEARING_TOML + "\n[connection.outter]\ntype = 'tube'\ninner_diameter_mm = 560.0\n")
    with pytest.raises(BearingDefinitionError) as info:
        load_bearing(p)
    message = str(info.value)
    assert "unknown table [connection.outter]" in message and "known: inner, outer" in message, message
    assert "{" not in message and "560" not in message, message      # not the table's content


def test_missing_key_of_a_subtable_is_named(tmp_path):
    p = tmp_path / "b.toml"
    p.write_text(BEARING_TOML + "\n[connection.outer]\ntype = 'tube'\ninner_diameter_mm = 560.0\n"
                 "outer_diameter_mm = 620.0\nyoungs_modulus_gpa = 210.0\npoisson_ratio = 0.3\n")
    with pytest.raises(BearingDefinitionError) as info:
        load_bearing(p)
    message = str(info.value)
    assert "[connection.outer]: missing key `length_mm`" in message and "None" not in message, message


BEARING_TOML = "\n".join(f"{k} = {v!r}" if not isinstance(v, str) else f'{k} = "{v}"'
                         for k, v in GOOD["bearing"].items())
BEARING_TOML = "[bearing]\n" + BEARING_TOML + "\n"


def test_missing_bearing_table_is_refused():
    with pytest.raises(BearingDefinitionError, match=r"missing table \[bearing\]"):
        bearing_from_dict({"material": {}})


def test_malformed_toml_is_refused(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("[bearing\npitch_diameter_mm = 1")
    with pytest.raises(BearingDefinitionError, match="not valid TOML"):
        load_bearing(p)


def test_si_round_trip():
    b = bearing_from_dict(GOOD)
    again = Bearing.from_si_dict(b.to_dict())
    assert again.to_dict() == b.to_dict()
