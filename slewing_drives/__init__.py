"""Pitch and yaw drives co-simulated with the slewing bearing FMU.

* :mod:`slewing_drives.drive` -- electric drive models (python-control linear model)
* :mod:`slewing_drives.load_series` -- bearing load time series (CSV, synthetic)
* :mod:`slewing_drives.cosimulation` -- fmpy step loop with the bearing FMU, plots
"""
from .drive import DriveParameters, ElectricDrive, linear_model
from .load_series import LoadSeries, synthetic_blade_root_loads, synthetic_tower_top_loads

__all__ = ["DriveParameters", "ElectricDrive", "linear_model", "LoadSeries", "synthetic_blade_root_loads",
           "synthetic_tower_top_loads"]
