"""Write tests/data/rosco/sim_reference.npz: ROSCO's own simulator on a 600 s turbulent wind.

ROSCO's simulator (``rosco.toolbox.sim.Sim.sim_ws_series``: a one-degree-of-freedom rotor
with the NREL 5 MW rotor performance table and ROSCO's library in the loop, ideal pitch
actuators) run on a seeded Kaimal wind series; ``tests/test_turbine_rosco_sim.py`` checks
``slewing_turbine.simulate_like_rosco_sim`` against it.

Needs the full ``rosco`` install (its toolbox imports wisdem and openmdao: about 3 minutes
and 1.4 GB, Python >= 3.11), not the project's environment::

    python3.11 -m venv /tmp/rosco-full && /tmp/rosco-full/bin/pip install rosco==2.10.6
    nice -n 10 /tmp/rosco-full/bin/python references/rosco/sim_reference.py    # from the repository root

Run time: 1.5-3 minutes (25-60 s of imports, 65-110 s for Sim's 60,000 steps). Nothing is
written besides the .npz (ROSCO runs in a temporary directory with a parameter copy
whose logging is off).

Wind: IEC 61400-1 ed. 3 normal turbulence model, Kaimal spectrum of the longitudinal
component at hub height (90 m), class B (I_ref 0.14), mean 13 m/s, 600 s at 10 ms, seed 1;
inverse FFT with phases from ``numpy.random.default_rng(seed)`` (:func:`kaimal_series`).
The series is stored (float64), so the test does not depend on regenerating it.
"""
import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
TURBINE = ROOT / "examples" / "turbines" / "nrel5mw"


def kaimal_series(mean=13.0, duration=600.0, dt=0.01, seed=1, i_ref=0.14, hub_height=90.0):
    """Seeded Kaimal series of the longitudinal wind at one point, m/s (IEC 61400-1 ed. 3 NTM).

    sigma_1 = I_ref (0.75 U + 5.6); Lambda_1 = 0.7 z (z < 60 m) else 42 m; L_u = 8.1 Lambda_1;
    S_u(f) = 4 sigma_1^2 (L_u / U) / (1 + 6 f L_u / U)^(5/3); random phases, inverse real FFT.
    """
    n = int(round(duration / dt))
    f = np.fft.rfftfreq(n, dt)[1:]
    sigma = i_ref * (0.75 * mean + 5.6)
    length = 8.1 * (0.7 * hub_height if hub_height < 60 else 42.0)
    spectrum = 4 * sigma**2 * length / mean / (1 + 6 * f * length / mean) ** (5 / 3)
    df = 1.0 / (n * dt)
    rng = np.random.default_rng(seed)
    amplitude = np.sqrt(spectrum * df / 2) * n   # one-sided spectrum -> irfft amplitudes
    phase = rng.uniform(0, 2 * np.pi, f.size)
    x = np.zeros(n // 2 + 1, complex)
    x[1:] = amplitude * np.exp(1j * phase)
    return np.arange(n) * dt, mean + np.fft.irfft(x, n)


def quiet_discon(source: Path, target: Path) -> None:
    """Copy DISCON.IN with LoggingLevel 0 and an absolute PerfFileName."""
    out = []
    for line in source.read_text(encoding="latin-1").splitlines():
        if "! LoggingLevel" in line:
            line = "0" + line[line.index(" "):]
        elif "! PerfFileName" in line:
            line = f'"{(source.parent / "Cp_Ct_Cq.NREL5MW.txt").resolve()}"' + line[line.index("   "):]
        out.append(line)
    target.write_text("\n".join(out) + "\n", encoding="latin-1")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", default=str(ROOT / "tests" / "data" / "rosco" / "sim_reference.npz"))
    args = ap.parse_args()

    t0 = time.perf_counter()
    import rosco
    from rosco import discon_lib_path
    from rosco.toolbox import control_interface, sim, turbine
    from rosco.toolbox.inputs.validation import load_rosco_yaml
    from importlib.metadata import version
    print(f"rosco {version('rosco')} imported in {time.perf_counter() - t0:.0f} s")

    examples = Path(rosco.__file__).resolve().parents[1] / "Examples"
    case = examples / "Test_Cases" / "NREL-5MW"
    params = load_rosco_yaml(str(examples / "Tune_Cases" / "NREL5MW.yaml"))
    t, ws = kaimal_series()
    dt = t[1] - t[0]
    output = Path(args.output).resolve()
    cwd = os.getcwd()
    work = tempfile.mkdtemp(prefix="rosco-sim-")
    try:
        os.chdir(work)
        wt = turbine.Turbine(params["turbine_params"])
        wt.load_from_fast("NREL-5MW.fst", str(case), rot_source="txt",
                          txt_filename=str(TURBINE / "Cp_Ct_Cq.NREL5MW.txt"))
        quiet_discon(TURBINE / "DISCON.IN", Path(work) / "DISCON.IN")
        ci = control_interface.ControllerInterface(discon_lib_path, param_filename=str(Path(work) / "DISCON.IN"),
                                                   sim_name="reference", DT=dt)
        s = sim.Sim(wt, ci)
        t1 = time.perf_counter()
        s.sim_ws_series(t, ws, rotor_rpm_init=10, init_pitch=0.0, make_plots=False)
        print(f"Sim.sim_ws_series: {t.size} steps in {time.perf_counter() - t1:.0f} s")
    finally:
        os.chdir(cwd)
        shutil.rmtree(work, ignore_errors=True)

    import scipy
    output.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(
        output,
        dt=dt, wind_speed=ws,
        rotor_speed=s.rot_speed.astype(np.float32), pitch=s.bld_pitch.astype(np.float32),
        generator_torque=s.gen_torque.astype(np.float32),
        J=wt.J, Ng=wt.Ng, GenEff=wt.GenEff, GBoxEff=wt.GBoxEff, rho=wt.rho, R=wt.rotor_radius,
        wind="IEC 61400-1 ed.3 NTM Kaimal, hub 90 m, class B (I_ref 0.14), mean 13 m/s, 600 s at 10 ms, seed 1",
        versions=(f"rosco {version('rosco')}, numpy {np.__version__}, scipy {scipy.__version__}, "
                  f"Python {sys.version.split()[0]}"))
    rpm = s.rot_speed * 30 / np.pi
    print(f"wrote {output} ({output.stat().st_size / 1e3:.0f} kB): wind {ws.mean():.2f} +- {ws.std():.2f} m/s, "
          f"rotor {rpm.min():.2f}-{rpm.max():.2f} rpm, pitch {np.degrees(s.bld_pitch).max():.1f} deg max")


if __name__ == "__main__":
    main()
