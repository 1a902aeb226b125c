"""The turbine loop with its three pitch bearings as FMUs (slewing_turbine.fmu_bearing) against the same loop with
the library's simulators: the same pitch, friction and rotor speed, the figures the FMU cannot give left out."""
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

if sys.version_info < (3, 11):
    pytest.skip("the turbine loop needs rosco 2.10.6, which needs Python >= 3.11", allow_module_level=True)
pytest.importorskip("rosco", reason="the turbine loop needs ROSCO's library: pip install --no-deps rosco==2.10.6")
pytest.importorskip("fmpy")
pytest.importorskip("pythonfmu")

from slewing_turbine import loop  # noqa: E402
from slewing_turbine.fmu_bearing import FmuBearing, fmu_bearings  # noqa: E402
from slewing_turbine.wind import kaimal  # noqa: E402

from conftest import ROOT  # noqa: E402

DT = 0.01
T_END = 2.0
#: relative agreement of the two routes (over each history's largest value). In a Python host the FMU's slave
#: runs this process's slewing_model and its loops (one CPython a process), so the two routes compute the same
#: numbers and agree exactly; 1e-9 leaves room for a host whose FMU runs the loops it carries compiled ahead
#: of time, which agree with numba's to round-off
RTOL = 1e-9


@pytest.fixture(scope="module")
def pitch_fmu(tmp_path_factory):
    """The example pitch bearing's FMU (FMI 2.0, standalone, loops compiled ahead of time where numba is
    installed) with the coarse superelement and free rings, no win64 half: the loop's coarse bearings."""
    sys.path.insert(0, str(ROOT))
    from build_fmu import build_fmu

    return build_fmu(loop.PITCH_BEARING, tmp_path_factory.mktemp("fmu") / "SlewingBearing_pitch.fmu", mesh="coarse",
                     bc="free", win64=False)


def test_the_fmu_route_gives_the_library_loop(pitch_fmu):
    """2 s of the closed loop in seeded class B turbulence (13 m/s), electric drives on flexible pitch bearings
    (coarse mesh), friction and the life accumulators on: the bearings as FMUs (:func:`fmu_bearings`) give the
    pitch, pitch rate, motor and friction torques, rotor speed and bearing map damage of the library's
    simulators (:func:`loop.make_bearings`). The FMU gives no load distribution: no contact patches, no
    ``x/2b`` figure; the other figures are there."""
    config = loop.TurbineConfig(mesh="coarse", life=True)
    wind = kaimal(13.0, T_END + 1.0, DT, seed=63)
    kwargs = dict(t_end=T_END, dt=DT, drives="electric", bearings="flexible", aero="bem")
    library = loop.run_turbine(config, wind, bearing_simulators=loop.make_bearings(config, "flexible", True), **kwargs)
    with fmu_bearings(config, pitch_fmu, "flexible", friction=True, dt=DT) as sims:
        fmu = loop.run_turbine(config, wind, bearing_simulators=sims, **kwargs)
        assert all(isinstance(s, FmuBearing) for s in sims)
        assert not any("error" in m.lower() for s in sims for m in s.messages)
    assert np.max(library.friction_torque[1:]) > 1e3                   # N m: friction on, the blades pitching
    assert np.ptp(library.pitch[1:]) > math.radians(0.1)
    for name in ("pitch", "pitch_rate", "friction_torque", "motor_torque", "rotor_speed", "generator_torque"):
        a, b = getattr(library, name)[1:], getattr(fmu, name)[1:]
        np.testing.assert_allclose(b, a, rtol=0.0, atol=RTOL * np.max(np.abs(a)), err_msg=name)
    damage_library = [a.worst_damage for a in library.life]
    damage_fmu = [a.worst_damage for a in fmu.life]
    assert max(damage_library) > 0.0
    np.testing.assert_allclose(damage_fmu, damage_library, rtol=1e-7)    # the FMU's life_damage output
    assert library.contact_b is not None and fmu.contact_b is None and fmu.contact_angle is None
    s_library, s_fmu = loop.summary(library), loop.summary(fmu)
    assert "x/2b below 1, worst blade [%]" in s_library and "x/2b below 1, worst blade [%]" not in s_fmu
    for key in ("friction torque peak [kN m]", "pitch tracking error RMS [deg]", "rotor speed mean [rpm]",
                "bearing map damage, worst blade"):
        assert s_fmu[key] == pytest.approx(s_library[key], rel=1e-7), key
    with pytest.raises(ValueError, match="bearing FMUs do not"):
        loop.wear_cycles(fmu, 0)


#: the FMU route in a process of its own, where the FMU's slewing_model comes first: a first instance is made
#: before anything imports slewing_model (pythonfmu puts the FMU's resources first on sys.path), so that this
#: process's library, the loop's and the FMUs', is the FMU's copy with the loops it carries
OWN_COPY = """
import json, os, sys
fmu, unzipdir, out, t_end = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
root = sys.path.pop(sys.path.index(os.environ["SLEWING_ROUTE_ROOT"]))
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
md = read_model_description(fmu)
first = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu, unzipdir),
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName="first")
first.instantiate()
sys.path.insert(1, root)
import numpy as np
import slewing_model
from slewing_model.numerics.compiled import aot_target
from slewing_turbine import loop
from slewing_turbine.fmu_bearing import fmu_bearings
from slewing_turbine.wind import kaimal
config = loop.TurbineConfig(mesh="coarse")
with fmu_bearings(config, fmu, "flexible", friction=True) as sims:
    r = loop.run_turbine(config, kaimal(13.0, t_end + 1.0, 0.01, seed=63), t_end=t_end, dt=0.01, drives="electric",
                         bearings="flexible", aero="bem", bearing_simulators=sims)
first.freeInstance()                      # instantiated only: no terminate
np.savez(out, **{k: getattr(r, k) for k in ("pitch", "pitch_rate", "friction_torque", "motor_torque", "rotor_speed")})
print(json.dumps({"library": slewing_model.__file__, "aot": aot_target()}))
"""


def test_the_fmus_own_library_and_loops_give_the_library_loop(pitch_fmu, tmp_path):
    """The independent path: the loop through the FMUs in a process where the FMUs run their own copy of
    slewing_model and the loops they carry (compiled ahead of time where numba is installed), against the
    library's loop here (numba's loops). They agree to round-off (measured: 1e-16 of each history's largest
    value over 10 s), well within :data:`RTOL`."""
    config = loop.TurbineConfig(mesh="coarse")
    library = loop.run_turbine(config, kaimal(13.0, T_END + 1.0, DT, seed=63), t_end=T_END, dt=DT, drives="electric",
                               bearings="flexible", aero="bem",
                               bearing_simulators=loop.make_bearings(config, "flexible", True))
    env = dict(os.environ, PYTHONPATH=str(ROOT), SLEWING_ROUTE_ROOT=str(ROOT))
    run = subprocess.run([sys.executable, "-c", OWN_COPY, str(pitch_fmu), str(tmp_path / "first"),
                          str(tmp_path / "route.npz"), str(T_END)], capture_output=True, text=True, env=env,
                         cwd=tmp_path, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    where = json.loads(run.stdout.strip().splitlines()[-1])
    if not where["library"].startswith(str(tmp_path / "first")):
        pytest.skip(f"the FMU's own slewing_model did not come first in its process ({where['library']})")
    if "numba" in sys.modules:
        assert where["aot"] is not None                   # the loops compiled ahead of time ran in the FMUs
    fmu = np.load(tmp_path / "route.npz")
    for name in fmu.files:
        a, b = getattr(library, name)[1:], fmu[name][1:]
        np.testing.assert_allclose(b, a, rtol=0.0, atol=RTOL * np.max(np.abs(a)), err_msg=name)


def test_an_fmu_of_another_build_is_refused(pitch_fmu):
    """The FMU's superelement is the coarse one: a loop configured for the fine mesh refuses it, naming both;
    as one configured for another bearing."""
    with pytest.raises(ValueError, match="coarse mesh .* the fine mesh"):
        with fmu_bearings(loop.TurbineConfig(mesh="fine"), pitch_fmu, "flexible", friction=True):
            pass
    other = ROOT / "examples" / "bearings" / "table3.toml"
    with pytest.raises(ValueError, match="another bearing"):
        with fmu_bearings(loop.TurbineConfig(mesh="coarse", bearing=other), pitch_fmu, "flexible", friction=True):
            pass
