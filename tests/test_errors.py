"""Manufacturing errors: CSV tables, periodic interpolation, synthetic generator, their effect."""
import math

import numpy as np
import pytest

from slewing_model import BearingDefinitionError, Loads, bearing_from_dict, load_bearing, solve, synthetic_errors
from slewing_model.distribution.assembly import assemble, cage_ratio
from slewing_model.bearing.manufacturing import (ManufacturingErrors, RingErrorMap, read_ball_csv, read_ring_csv,
                                  write_ring_csv)


def _ring_map(values=(0.0,)):
    theta = np.radians([0.0, 90.0, 180.0, 270.0])
    radial = np.column_stack([[1e-6, 2e-6, 3e-6, 4e-6], [0, 0, 0, 0]])
    return RingErrorMap(theta, radial, np.zeros((4, 2)))


def test_interpolation_is_linear_and_periodic():
    m = _ring_map()
    radial, _, _ = m.at(np.radians([45.0, 315.0, 360.0 + 45.0, -45.0]))
    assert np.allclose(radial[:, 0], [1.5e-6, 2.5e-6, 1.5e-6, 2.5e-6])


def test_interpolation_of_an_unsorted_table_across_zero():
    # the table in any order and past 360 deg; between 350 and 370 (= 10) deg the values blend linearly
    theta = np.radians([370.0, 100.0, 350.0, 200.0])
    radial = np.column_stack([[1e-6, 5e-6, 3e-6, 7e-6], [0.0, 1e-6, 0.0, 1e-6]])
    axial = -radial
    groove = 1e-3 + radial
    m = RingErrorMap(theta, radial, axial, groove)
    r, a, g = m.at(np.radians([0.0, 355.0, -5.0, 720.0 + 150.0]))
    assert np.allclose(r[:, 0], [2e-6, 2.5e-6, 2.5e-6, 6e-6], rtol=1e-12)
    assert np.allclose(a[:, 0], -r[:, 0]) and np.allclose(g[:, 0], 1e-3 + r[:, 0])
    assert np.allclose(r[:, 1], [0.0, 0.0, 0.0, 1e-6], atol=1e-18)


def test_ring_csv_round_trip(tmp_path):
    errors = synthetic_errors(10, seed=3, groove_radius_amplitude=2e-6, nominal_groove_radius=[0.01325] * 4)
    path = tmp_path / "outer.csv"
    write_ring_csv(path, "outer", errors.outer)
    again = read_ring_csv(path, "outer")
    assert np.allclose(again.radial, errors.outer.radial, atol=1e-12)
    assert np.allclose(again.groove_radius, errors.outer.groove_radius, atol=1e-9)


def test_synthetic_errors_repeat_with_the_seed():
    a, b, c = synthetic_errors(67, seed=7), synthetic_errors(67, seed=7), synthetic_errors(67, seed=8)
    assert np.array_equal(a.inner.axial, b.inner.axial) and np.array_equal(a.ball_diameter_deviation, b.ball_diameter_deviation)
    assert not np.allclose(a.inner.axial, c.inner.axial)
    assert np.all(np.abs(a.ball_diameter_deviation) <= 2e-6)


def test_zero_errors_are_the_nominal_bearing(table3):
    zero = synthetic_errors(table3.ball_count, radial_amplitude=0.0, axial_amplitude=0.0, ball_tolerance=0.0)
    loads = Loads(Fz=3e4, Mx=1e4)
    a = solve(table3, loads)
    b = solve(table3.with_errors(zero), loads)
    assert np.allclose(a.contact_load, b.contact_load, rtol=1e-12, atol=0.0)


def test_uniform_groove_shift_changes_interference_by_geometry(table3):
    # every outer groove centre (contacts 1 and 4) moved radially outwards by u: both diagonals
    # change length by |e0 - (u, 0)| - |e0|; the change is symmetric about the ball plane and
    # uniform, so the inner ring has no rigid motion that undoes it and stays where it is
    u = 5e-6
    theta = np.radians([0.0, 120.0, 240.0])
    radial = np.full((3, 2), u)
    errors = ManufacturingErrors(outer=RingErrorMap(theta, radial, np.zeros((3, 2))))
    r = solve(table3.with_preload(30e-6).with_errors(errors))
    a = 2 * table3.groove_radius[0] - table3.ball_diameter
    e0 = a * np.array([math.cos(table3.contact_angle), math.sin(table3.contact_angle)])
    expected = 30e-6 + np.linalg.norm(e0 - [u, 0.0]) - a
    assert np.allclose(r.interference, expected, rtol=1e-9)
    assert np.allclose(r.displacement, 0.0, atol=1e-13)


def test_errors_turn_with_their_ring(table3):
    errors = synthetic_errors(table3.ball_count, seed=1)
    bearing = table3.with_errors(errors)
    psi = 0.3
    a = assemble(bearing, psi)
    phi = a.ball_angle
    assert np.allclose(phi, table3.ball_angles + cage_ratio(table3) * psi)
    # moving (inner) ring read at its own angle phi - psi, outer ring at phi
    r_in, z_in, _ = errors.inner.at(phi - psi)
    r_out, _, _ = errors.outer.at(phi)
    assert np.allclose(a.groove_centre[:, 2, 0] - table3.groove_centres[2, 0], r_in[:, 1])
    assert np.allclose(a.groove_centre[:, 0, 0] - table3.groove_centres[0, 0], r_out[:, 0])


@pytest.mark.parametrize("errors", ["none", "balls", "rings", "radii"])
def test_assembly_at_another_rotation_equals_one_made_anew(table3, errors):
    """Reassembling from the assembly at another rotation (what a solver does each step) gives
    what assembling anew gives: without ring errors only the angles change (ball diameter
    deviations turn with their balls), with them the grooves under the balls are read again,
    and with measured groove radii their stiffnesses too."""
    synthetic = synthetic_errors(table3.ball_count, seed=3)
    outer = synthetic.outer
    measured = RingErrorMap(outer.angle, outer.radial, outer.axial,
                            table3.groove_radius[0] * (1.0 + 1e-3 * np.sin(outer.angle))[:, None] * np.ones(2))
    bearing = {"none": table3,
               "balls": table3.with_errors(ManufacturingErrors(ball_diameter_deviation=synthetic.ball_diameter_deviation)),
               "rings": table3.with_errors(synthetic),
               "radii": table3.with_errors(ManufacturingErrors(outer=measured, inner=synthetic.inner))}[errors]
    previous = assemble(bearing, 0.2)
    for psi, cage in ((0.7, None), (-1.3, 0.4)):
        turned, fresh = assemble(bearing, psi, cage, previous=previous), assemble(bearing, psi, cage)
        for name in ("psi", "cage_angle", "ball_angle", "groove_centre", "groove_radius", "ball_diameter",
                     "contact_stiffness", "stiffness", "natural_length", "moving_sign"):
            assert np.array_equal(getattr(turned, name), getattr(fresh, name)), name
    assert (turned.groove_centre is previous.groove_centre) == (errors in ("none", "balls"))
    assert (turned.stiffness is previous.stiffness) == (errors != "radii")


def test_assembly_of_another_bearing_is_refused_as_previous(table3):
    from conftest import BEARINGS

    other = assemble(load_bearing(BEARINGS / "pitch_bearing.toml"))
    with pytest.raises(ValueError, match=r"previous: an assembly of 150 balls.*not of this bearing \(67 balls"):
        assemble(table3, 0.1, previous=other)


def test_definition_with_csv_errors(tmp_path):
    errors = synthetic_errors(67, seed=2)
    write_ring_csv(tmp_path / "outer.csv", "outer", errors.outer)
    write_ring_csv(tmp_path / "inner.csv", "inner", errors.inner)
    (tmp_path / "balls.csv").write_text("ball,diameter_deviation_um\n" +
                                        "".join(f"{i + 1},{d * 1e6:.6f}\n" for i, d in enumerate(errors.ball_diameter_deviation)))
    text = open("examples/bearings/table3.toml").read() + (
        '\n[errors]\nouter_ring_csv = "outer.csv"\ninner_ring_csv = "inner.csv"\nball_diameters_csv = "balls.csv"\n')
    (tmp_path / "b.toml").write_text(text)
    b = load_bearing(tmp_path / "b.toml")
    assert np.allclose(b.errors.ball_diameter_deviation, errors.ball_diameter_deviation, atol=1e-12)


@pytest.mark.parametrize("content,message", [
    ("angle_deg,radial_um_1,axial_um_1\n0,1,1\n", "column 'radial_um_4' is missing"),
    ("angle_deg,radial_um_1,axial_um_1,radial_um_4,axial_um_4\n0,1,1,1,1\n", "at least two angles"),
    ("angle_deg,radial_um_1,axial_um_1,radial_um_4,axial_um_4\n0,1,1,1,1\n10,x,1,1,1\n", "line 3, column radial_um_1 = 'x': must be a number"),
    ("angle_deg,radial_um_1,axial_um_1,radial_um_4,axial_um_4\n0,1,1,1,1\n10,nan,1,1,1\n", "must be finite"),
    ("angle_deg,radial_um_1,axial_um_1,radial_um_4,axial_um_4\n10,1,1,1,1\n5,1,1,1,1\n", "strictly increasing"),
    ("angle_deg,radial_um_1,axial_um_1,radial_um_4,axial_um_4\n0,1,1,1,1\n10,1,1\n", "3 values for 5 columns"),
])
def test_malformed_ring_file_is_refused(tmp_path, content, message):
    p = tmp_path / "ring.csv"
    p.write_text(content)
    with pytest.raises(BearingDefinitionError, match=message):
        read_ring_csv(p, "outer")


def test_ball_file_must_list_every_ball(tmp_path):
    p = tmp_path / "balls.csv"
    p.write_text("ball,diameter_deviation_um\n1,0.5\n2,0.1\n")
    with pytest.raises(BearingDefinitionError, match="2 balls listed, the bearing has ball_count = 3"):
        read_ball_csv(p, 3)


def test_unknown_synthetic_key_is_refused():
    d = {"bearing": {"pitch_diameter_mm": 541.0, "ball_diameter_mm": 25.0, "groove_radius_mm": 13.25,
                     "contact_angle_deg": 45.0, "ball_count": 67},
         "errors": {"synthetic": {"seed": 1, "amplitude": 3}}}
    with pytest.raises(BearingDefinitionError, match="errors.synthetic.amplitude = 3: unknown key"):
        bearing_from_dict(d)
