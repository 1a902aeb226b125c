"""Runs an SSP with fmpy's simulate_ssp (examples/ssp/ssp_hosts.run_fmpy) and prints the compared outputs: run by
the embeddable Windows Python under wine (tests/test_win64.py), its four FMUs' win64 binaries in one process.

    python ssp_run.py SSP STOP_TIME STEP_SIZE

Prints "<name> <value after each step, repr>..." lines, then "done"."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples", "ssp"))
from ssp_hosts import COMPARED, run_fmpy  # noqa: E402

out = run_fmpy(sys.argv[1], list(COMPARED), stop_time=float(sys.argv[2]), step_size=float(sys.argv[3]))
for name in ["time", *COMPARED]:
    print(name, *(repr(float(v)) for v in out[name]), flush=True)
print("done", flush=True)
