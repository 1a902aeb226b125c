"""Run the pitch system SSP in fmpy, libcosim and ecos, and compare with the Python co-simulation.

Builds ``examples/ssp/pitch_system.ssp`` (``build_ssp.py``) if it is not there, runs it in each
host that is installed, runs :func:`slewing_drives.cosimulation.run_manoeuvre` with the same step
sequence (``coupling="parallel"``, or ``"parallel-zero-start"`` for fmpy) and with its default
sequential coupling, prints the largest differences and plots ``results/pitch_system_ssp.png``.

    .venv/bin/python examples/ssp/run_ssp.py [--rigid] [--build] [--hosts fmpy,libcosim,ecos]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "examples"))

from build_ssp import PITCH_BEARING_PARAMETERS, build_pitch_system  # noqa: E402
from ssp_hosts import COMPARED, COUPLING, HOSTS, max_relative_difference, reference_values  # noqa: E402


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rigid", action="store_true", help="rigid rings (faster) instead of flexible rings")
    parser.add_argument("--build", action="store_true", help="build the SSP even if it exists")
    parser.add_argument("--hosts", default=",".join(HOSTS))
    parser.add_argument("--results", default=str(ROOT / "results"))
    args = parser.parse_args(argv)
    import pitch_manoeuvre as demo

    from slewing_drives import DriveParameters, LoadSeries
    from slewing_drives.cosimulation import run_manoeuvre

    ring_model = 1 if args.rigid else 2
    ssp = HERE / ("pitch_system_rigid.ssp" if args.rigid else "pitch_system.ssp")
    if args.build or not ssp.exists():
        build_pitch_system(ssp, ring_model=ring_model)
    bearing_fmu = ROOT / "build/SlewingBearing_pitch_bearing.fmu"
    drive = DriveParameters.from_toml(ROOT / "examples/drives/pitch_drive.toml")
    loads = LoadSeries.read_csv(ROOT / "examples/loads/blade_root_loads.csv")
    start = dict(PITCH_BEARING_PARAMETERS, ring_model=ring_model)
    references, runs = {}, {}
    for coupling in ("sequential", "parallel", "parallel-zero-start"):
        begin = time.perf_counter()
        references[coupling] = run_manoeuvre(bearing_fmu, drive, loads, demo.command, t_end=demo.T_END, dt=demo.DT,
                                             start_values=start, coupling=coupling)
        print(f"run_manoeuvre, coupling {coupling}: {time.perf_counter() - begin:.1f} s")
    for host in args.hosts.split(","):
        begin = time.perf_counter()
        try:
            runs[host] = HOSTS[host](ssp, list(COMPARED), stop_time=demo.T_END, step_size=demo.DT)
        except ImportError as exc:
            print(f"{host}: not installed ({exc})")
            continue
        print(f"{host}: {time.perf_counter() - begin:.1f} s")
    print("\n| host | run_manoeuvre coupling | " + " | ".join(COMPARED) + " |")
    print("|---|---|" + "---|" * len(COMPARED))
    for host, out in runs.items():
        r = references[COUPLING[host]]
        cells = [f"{max_relative_difference(out[n], reference_values(r, n)):.1e}" for n in COMPARED]
        print(f"| {host} | {COUPLING[host]} | " + " | ".join(cells) + " |")
    cells = [f"{max_relative_difference(reference_values(references['parallel'], n), reference_values(references['sequential'], n)):.1e}"
             for n in COMPARED]
    print("| run_manoeuvre parallel | sequential (default) | " + " | ".join(cells) + " |")
    print("(largest difference over the run, relative to the signal's largest magnitude)")
    path = Path(args.results) / "pitch_system_ssp.png"
    plot(runs, references, demo, drive, path)
    print(f"\nplot: {path}")
    return 0


def plot(runs, references, demo, drive, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path.parent.mkdir(parents=True, exist_ok=True)
    ref = references["parallel"]
    fig, ax = plt.subplots(4, 1, figsize=(9, 11), sharex=True)
    ax[0].plot(ref.time, np.degrees(ref.command), "k--", label="command")
    ax[0].plot(ref.time, np.degrees(references["sequential"].angle), "0.6", lw=3, label="run_manoeuvre (sequential)")
    styles = {"fmpy": ":", "libcosim": "-", "ecos": "--"}
    for host, out in runs.items():
        ax[0].plot(out["time"], np.degrees(out["drive.psi"]), styles.get(host, "-"), lw=1, label=f"SSP in {host}")
    ax[0].set_ylabel("pitch angle [deg]")
    ax[0].legend(loc="best")
    for host, out in runs.items():
        ax[1].plot(out["time"], out["drive.motor_torque"], styles.get(host, "-"), lw=1, label=f"SSP in {host}")
    ax[1].axhline(drive.torque_limit, color="r", lw=0.8, label="torque limit")
    ax[1].axhline(-drive.torque_limit, color="r", lw=0.8)
    ax[1].set_ylabel("motor torque [N m]")
    ax[1].legend(loc="best")
    for host, out in runs.items():
        ax[2].plot(out["time"], out["bearing.friction_torque_magnitude"] / 1e3, styles.get(host, "-"), lw=1,
                   label=f"SSP in {host}")
    ax[2].set_ylabel("bearing friction [kN m]")
    ax[2].legend(loc="best")
    for host, out in runs.items():
        r = references[COUPLING[host]]
        difference = np.abs(np.degrees(out["drive.psi"] - r.angle))
        ax[3].semilogy(out["time"], np.maximum(difference, 1e-18), styles.get(host, "-"), lw=1,
                       label=f"{host} - run_manoeuvre ({COUPLING[host]})")
    gap = np.abs(np.degrees(references["parallel"].angle - references["sequential"].angle))
    ax[3].semilogy(ref.time, np.maximum(gap, 1e-18), "0.5", lw=1, label="parallel - sequential coupling")
    ax[3].set_ylabel("|angle difference| [deg]")
    ax[3].set_xlabel("time [s]")
    ax[3].legend(loc="best", fontsize=8)
    fig.suptitle(f"pitch system SSP ({demo.STEP_DEG:g} deg step and back) in SSP hosts and in Python")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
