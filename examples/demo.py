"""`make demo`: the main job on a fresh machine.

Builds the FMU of the example pitch bearing (superelement included), runs a
pitch manoeuvre with the bearing in the loop, with and without its friction,
writes the plots to ``results/`` and prints the summary table.
"""
from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import pitch_manoeuvre  # noqa: E402

if __name__ == "__main__":
    sys.exit(pitch_manoeuvre.main())
