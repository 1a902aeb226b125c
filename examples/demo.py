"""`make demo`: the main job on a fresh machine.

Builds the FMU of the example pitch bearing (superelement included), runs a
pitch manoeuvre with the bearing in the loop, with and without its friction,
writes the plots to ``results/`` and prints the summary table.
"""
from __future__ import annotations

import sys
from pathlib import Path

# a line as each stage begins: on a fresh, loaded machine the FMU's build (superelement, the loops
# compiled ahead of time, the FMU's Python runtime) takes minutes before the first progress bar
print("make demo: loading the model (numpy, numba) ...", flush=True)
sys.path.insert(0, str(Path(__file__).resolve().parent))

import pitch_manoeuvre  # noqa: E402

if __name__ == "__main__":
    sys.exit(pitch_manoeuvre.main())
