"""The builds that the win64 and Debian 11 floor tests take from their caches, made where missing: `make test`
runs this before the suite, so that every platform the FMU claims is tested on a fresh machine too.

- the floor-lowered Linux runtime (tests/linux_floor/build.sh: CPython 3.11, pythonfmu's export library and
  fmusim in a Debian 11 build chroot; about 4 minutes the first time, kept in /var/cache/slewing-chroots);
- fmusim cross-compiled with mingw-w64 (tests/win64/build_fmusim.sh, about 5 minutes the first time, kept in
  /var/cache/slewing-wine) and the FMU's loops compiled ahead of time for win64 under wine
  (fmu_build.win64.aot_module, about 2.5 minutes the first time per version of the loops, kept in the aot cache).

The two lanes run side by side (2 cores): about 8 minutes the first time on a 2-core machine, a few seconds
after. They need root (debootstrap, chroot, apt-get) and wine and mingw-w64 (which `make` installs as root);
without them nothing is built and the tests that need the builds are skipped, saying why. A build that fails
fails this script (exit 1), with its output's end.

    .venv/bin/python tests/platform_builds.py
"""
from __future__ import annotations

import os
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import win64_tools as w  # noqa: E402

FLOOR_SCRIPT = HERE / "linux_floor" / "build.sh"


def floor_runtime() -> str:
    from test_standalone import bare_system

    bare_system("bullseye")         # the tests' bare Debian 11, which build.sh copies for its build chroot
    run = subprocess.run(["bash", str(FLOOR_SCRIPT)], capture_output=True, text=True, timeout=3600)
    if run.returncode != 0:
        raise RuntimeError(f"{FLOOR_SCRIPT.name} failed:\n{run.stderr[-3000:]}")
    return run.stdout.strip().splitlines()[-1]


def win64() -> str:
    import fmu_build.win64

    fmusim = w.build_fmusim()
    return f"{fmusim}, {fmu_build.win64.aot_module()}"


def why_not() -> str:
    """Why nothing can be built here ("" when it can)."""
    if os.geteuid() != 0:
        return "not root (debootstrap, chroot and apt-get need it)"
    return w.missing_tools()


def main() -> int:
    reason = why_not()
    if reason:
        print(f"platform builds: none made, {reason}: the win64 and Debian 11 floor tests are skipped")
        return 0
    os.environ.pop("SLEWING_WIN64_AOT_CACHED_ONLY", None)      # this step is where they are compiled
    lanes = {"Debian 11 floor runtime": floor_runtime, "win64 fmusim and loops": win64}
    failed = 0
    with ThreadPoolExecutor(len(lanes)) as pool:
        started = time.perf_counter()
        futures = {pool.submit(lane): name for name, lane in lanes.items()}
        for future in as_completed(futures):
            name = futures[future]
            try:
                made = future.result()
            except Exception as error:          # noqa: BLE001  (each lane's failure is reported, then exit 1)
                failed = 1
                print(f"platform builds: {name} FAILED: {error}", file=sys.stderr)
            else:
                print(f"platform builds: {name} ready after {time.perf_counter() - started:.0f} s: {made}")
    return failed


if __name__ == "__main__":
    sys.exit(main())
