"""The bearing in time: one co-simulation step after another (what the FMU wraps).

* :mod:`.simulator` -- :class:`BearingSimulator`: load distribution, friction torque and life,
  warm-started step to step, its state saved and restored.
"""
from .simulator import BearingSimulator, SimulatorSettings, StepResult

__all__ = ["BearingSimulator", "SimulatorSettings", "StepResult"]
