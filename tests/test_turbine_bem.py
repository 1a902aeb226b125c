"""The blade-element-momentum model (slewing_turbine.bem) against momentum theory and ROSCO's rotor table.

Expected values come from outside the module: the momentum equations written out here, the input
files' own numbers, and the NREL 5MW rotor performance table that ROSCO's toolbox computed with
CCBlade (examples/turbines/nrel5mw/Cp_Ct_Cq.NREL5MW.txt).
"""
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from slewing_turbine.bem import Blade, Polar, RotorGeometry, bem_loads, node_heights, read_polar

CASE = Path(__file__).resolve().parents[1] / "examples" / "turbines" / "nrel5mw"
TABLE = CASE / "Cp_Ct_Cq.NREL5MW.txt"


@pytest.fixture(scope="module")
def rotor():
    return RotorGeometry.read_toml(CASE / "rotor.toml")


@pytest.fixture(scope="module")
def blade(rotor):
    return rotor.read_blade()


def read_table(path):
    """ROSCO's rotor performance file: pitch (deg), TSR, Cp and Ct matrices (rows: TSR)."""
    lines = path.read_text().splitlines()

    def after(tag):
        return next(k for k, line in enumerate(lines) if tag in line)

    pitch = np.array(lines[after("Pitch angle vector") + 1].split(), float)
    tsr = np.array(lines[after("TSR vector") + 1].split(), float)
    wind = float(lines[after("Wind speed vector") + 1].split()[0])

    def matrix(tag):
        k = after(tag) + 2
        return np.array([line.split() for line in lines[k:k + tsr.size]], float)

    return pitch, tsr, wind, matrix("Power coefficient"), matrix("Thrust coefficient")


def test_reads_the_aerodyn_blade_and_its_polars(blade, rotor):
    # the numbers of NRELOffshrBsline5MW_AeroDyn_blade.dat (19 nodes) and of the airfoil files
    assert blade.span.size == 19
    assert blade.span[0] == 0.0 and blade.span[-1] == pytest.approx(61.4999)
    assert blade.chord[0] == pytest.approx(3.542) and blade.chord[-1] == pytest.approx(1.419)
    assert math.degrees(blade.twist[0]) == pytest.approx(13.308)
    assert blade.ac_edge[5] == pytest.approx(-0.56986665)
    assert [p.name for p in blade.polars] == [Path(a).stem for a in rotor.airfoils]
    du21 = read_polar(CASE / "Airfoils" / "DU21_A17.dat")
    assert du21.alpha.size == 142                                   # NumAlf
    assert math.degrees(du21.alpha[0]) == -180.0 and du21.cm[1] == pytest.approx(0.1978)
    assert rotor.hub_height == 90.0 and math.degrees(rotor.precone) == pytest.approx(-2.5)


@pytest.mark.skipif(not TABLE.exists(), reason="examples/turbines/nrel5mw/Cp_Ct_Cq.NREL5MW.txt is not there")
@pytest.mark.parametrize("pitch_deg, tsr", [(0.0, 7.5), (0.0, 6.0), (2.0, 8.0), (3.0, 6.0), (5.0, 6.0),
                                            (10.0, 5.0), (15.0, 4.0)])
def test_power_and_thrust_coefficients_against_rosco_table(blade, pitch_deg, tsr):
    """Cp and Ct of the rotor (3 blades, averaged over 8 azimuths as the table's CCBlade run:
    ``nSector = 8``, precone 2.5 deg, tilt 5 deg, shear exponent 0.2, hub height TowerHt + Twr2Shft =
    89.56 m, rated wind 11.4 m/s; coefficients on CCBlade's area pi (R cos(precone))^2) within 4 %.
    What is left between the two BEMs: CCBlade fits its polars with a smoothing spline (s = 0.1)
    where AeroDyn (and we) interpolate linearly, and it treats the end nodes differently. Measured:
    Cp -2.9 .. +1.2 %, Ct -1.7 .. +0.5 % (without precone, tilt and shear Cp is +2 .. +6 % off)."""
    pitch, tsrs, wind, cp, ct = read_table(TABLE)
    row, col = np.flatnonzero(np.isclose(tsrs, tsr))[0], np.flatnonzero(np.isclose(pitch, pitch_deg))[0]
    hub = 89.56
    omega = tsr * wind / blade.tip_radius
    power = thrust = 0.0
    for azimuth in np.arange(8) * math.pi / 4:
        z = node_heights(blade, azimuth, hub)
        aero = bem_loads(blade, wind * (z / hub) ** 0.2, omega, math.radians(pitch_deg), azimuth=azimuth)
        assert aero.unbracketed == 0
        power += 3 * aero.torque_contribution * omega / 8
        thrust += 3 * aero.thrust / 8
    area = math.pi * (blade.tip_radius * math.cos(blade.precone)) ** 2
    q = 0.5 * blade.air_density * wind**2
    assert power / (q * area * wind) == pytest.approx(cp[row, col], rel=0.04)
    assert thrust / (q * area) == pytest.approx(ct[row, col], rel=0.04)


def prandtl(blade, r, phi):
    """Tip times hub loss (Prandtl, as Ning eq. A4), written out again here."""
    s = np.abs(np.sin(phi))
    n = blade.blade_count
    tip = 2 / np.pi * np.arccos(np.exp(-n / 2 * (blade.tip_radius - r) / (r * s)))
    hub = 2 / np.pi * np.arccos(np.exp(-n / 2 * (r - blade.hub_radius) / (blade.hub_radius * s)))
    return tip * hub


@pytest.mark.parametrize("wind, omega, pitch_deg", [(8.0, 0.95, 0.0), (11.4, 1.267, 0.0), (16.0, 1.267, 10.0)])
def test_annulus_momentum_balance(blade, wind, omega, pitch_deg):
    """With polars without drag (AeroDyn's AIDrag/TIDrag False then make the loads equal the induction's
    forces), no cone and no tilt, every annulus obeys momentum theory with Prandtl's F:
    thrust ``B N' = 4 pi r rho V^2 a (1 - a) F`` and torque ``B T' r = 4 pi r^3 rho V Omega a' (1 - a) F``
    where ``a <= 0.4``, and Buhl's ``C_T = 8/9 + (4F - 40/9) a + (50/9 - 4F) a^2`` above; the inflow
    angle closes the velocity triangle ``tan(phi) = V (1 - a) / (Omega r (1 + a'))``."""
    polars = tuple(Polar(p.name, p.alpha, p.cl, np.zeros_like(p.cd), p.cm) for p in blade.polars)
    clean = dataclasses.replace(blade, polars=polars, precone=0.0, shaft_tilt=0.0)
    aero = bem_loads(clean, wind, omega, math.radians(pitch_deg))
    r = clean.hub_radius + clean.span
    a, ap, phi = aero.axial_induction, aero.tangential_induction, aero.inflow_angle
    inner = (clean.span > 0) & (r < clean.tip_radius - 1e-3)        # the loss factor is 0 at the hub node
    rho, n = clean.air_density, clean.blade_count
    f = prandtl(clean, r, phi)
    assert aero.unbracketed == 0
    np.testing.assert_allclose(aero.loss_factor[inner], f[inner], rtol=1e-12)
    lift = inner & (np.abs(aero.normal) > 1.0)                     # the cylinders (Cl = 0) carry nothing
    assert lift.sum() >= 12
    np.testing.assert_allclose(np.tan(phi[lift]), wind * (1 - a[lift]) / (omega * r[lift] * (1 + ap[lift])),
                               rtol=1e-7)
    light = lift & (a <= 0.4)
    np.testing.assert_allclose(n * aero.normal[light], 4 * np.pi * r[light] * rho * wind**2 * a[light]
                               * (1 - a[light]) * f[light], rtol=1e-7)
    np.testing.assert_allclose(n * aero.tangential[light] * r[light], 4 * np.pi * r[light] ** 3 * rho * wind
                               * omega * ap[light] * (1 - a[light]) * f[light], rtol=1e-7)
    heavy = lift & (a > 0.4)
    ct_local = n * aero.normal[heavy] / (0.5 * rho * wind**2 * 2 * np.pi * r[heavy])
    buhl = 8 / 9 + (4 * f[heavy] - 40 / 9) * a[heavy] + (50 / 9 - 4 * f[heavy]) * a[heavy] ** 2
    np.testing.assert_allclose(ct_local, buhl, rtol=1e-6)


def test_betz_limit_of_an_ideal_rotor():
    """Actuator-disc limit. Without losses, drag and wake rotation the BEM's momentum equation is the
    actuator disc's. A blade laid out by hand for a = 1/3 at every radius (velocity triangle
    ``tan(phi) = (1 - a) / lambda_r``, chord from ``k = a / (1 - a) = sigma' c_l cos(phi) / (4 sin^2 phi)``,
    twist ``phi - alpha_design``) must come out of the solver with a = 1/3 everywhere and with Betz's
    power coefficient 16/27 on the annulus it covers, ``1 - (R_hub / R)^2`` of the disc."""
    alpha = np.radians(np.linspace(-180, 180, 3601))
    polar = Polar("ideal", alpha, np.pi * np.sin(2 * alpha), np.zeros_like(alpha), np.zeros_like(alpha))
    alpha_design = math.radians(6.0)
    cl_design = math.pi * math.sin(2 * alpha_design)
    hub, tip, blades, wind, tsr = 1.5, 63.0, 3, 10.0, 8.0
    omega = tsr * wind / tip
    span = np.linspace(0.0, tip - hub, 400)
    r = hub + span
    phi = np.arctan((1 - 1 / 3) / (omega * r / wind))
    chord = 0.5 * 4 * np.sin(phi) ** 2 / np.cos(phi) * 2 * np.pi * r / (blades * cl_design)
    ideal = Blade(span=span, chord=chord, twist=phi - alpha_design, airfoil=np.zeros(span.size, dtype=np.int64),
                  ac_flap=np.zeros(span.size), ac_edge=np.zeros(span.size), polars=(polar,), hub_radius=hub,
                  tip_radius=tip, blade_count=blades)
    aero = bem_loads(ideal, wind, omega, 0.0, tip_loss=False, hub_loss=False, tangential_induction=False,
                     cone=0.0, tilt=0.0)
    np.testing.assert_allclose(aero.axial_induction, 1 / 3, rtol=1e-6)
    cp = blades * aero.torque_contribution * omega / (0.5 * 1.225 * math.pi * tip**2 * wind**3)
    assert cp == pytest.approx(16 / 27 * (1 - (hub / tip) ** 2), rel=1e-4)


@pytest.mark.parametrize("wind, omega, pitch_deg", [(3.0, 0.0, 90.0), (25.0, 0.0, 90.0), (0.0, 1.2, 0.0),
                                                    (4.0, 1.27, -3.0), (25.0, 1.27, 25.0), (25.0, 1.27, 0.0),
                                                    (6.0, 1.6, 0.0), (40.0, 0.2, 0.0)])
def test_every_node_converges(blade, wind, omega, pitch_deg):
    """Parked, idling, no wind, stalled, over-speed: a root in a bracket at every node, finite loads."""
    aero = bem_loads(blade, wind, omega, math.radians(pitch_deg), azimuth=1.0)
    assert aero.unbracketed == 0
    values = np.concatenate([aero.normal, aero.tangential, aero.pitching_moment,
                             [aero.root_flap, aero.root_edge, aero.torque_contribution, aero.thrust]])
    assert np.all(np.isfinite(values))
    if wind == 0.0 and omega == 0.0:
        assert not values.any()


def test_root_sums_and_shear_input(blade):
    """The root moments are the trapezoidal integrals of the nodes' loads (as AeroDyn maps line loads
    to the root); a sheared input changes the blade's loads with its azimuth."""
    aero = bem_loads(blade, 12.0, 1.2, math.radians(2.0))
    s = blade.span
    assert aero.root_flap == pytest.approx(np.trapezoid(aero.normal * s, s), rel=1e-12)
    assert aero.root_edge == pytest.approx(np.trapezoid(aero.tangential * s, s), rel=1e-12)
    r = (blade.hub_radius + s) * math.cos(blade.precone)
    assert aero.torque_contribution == pytest.approx(np.trapezoid(aero.tangential * r, s), rel=1e-12)
    up = bem_loads(blade, 12.0 * (node_heights(blade, 0.0, 90.0) / 90.0) ** 0.2, 1.2, math.radians(2.0))
    down = bem_loads(blade, 12.0 * (node_heights(blade, math.pi, 90.0) / 90.0) ** 0.2, 1.2, math.radians(2.0),
                     azimuth=math.pi)
    assert up.root_flap > aero.root_flap > down.root_flap
    with pytest.raises(ValueError):
        bem_loads(blade, np.ones(5), 1.2, 0.0)
