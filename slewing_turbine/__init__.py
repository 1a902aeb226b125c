"""A wind turbine around the pitch and yaw bearings: ROSCO's controller, rotor, wind, blade loads.

* :mod:`slewing_turbine.controller` -- ROSCO (NREL's controller library) called in process
* :mod:`slewing_turbine.rotor` -- rigid drivetrain, rotor performance table, ROSCO's simulator loop
* :mod:`slewing_turbine.wind` -- hub-height wind: IEC turbulence (Kaimal), gusts, steps, shear
* :mod:`slewing_turbine.bem` -- steady blade-element-momentum aerodynamics of each blade
* :mod:`slewing_turbine.blade_loads` -- blade-root loads (aerodynamics, gravity, centrifugal) and the pitch
  bearing's inputs from them
* :mod:`slewing_turbine.loop` -- the closed loop: controller, rotor, three pitch drives and pitch bearings
* :mod:`slewing_turbine.fmu_bearing` -- the loop's pitch bearings as bearing FMUs (fmpy; not imported here)
"""
from .controller import Commands, Measurements, RoscoController, RoscoError, read_discon
from .rotor import CpTable, Drivetrain, RotorSimResult, aerodynamic_torque, euler_step, simulate_like_rosco_sim
from .wind import (WindSeries, blade_height, extreme_direction_change, extreme_operating_gust, kaimal, read_wind,
                   shear, steady, step_change, write_wind)
from .bem import Blade, BladeAero, Polar, RotorGeometry, bem_loads, node_heights, read_polar
from .blade_loads import BladeMass, RootLoads, bearing_inputs, bearing_load_series, root_loads
from .loop import TurbineConfig, TurbineResult, run_turbine

__all__ = ["Commands", "Measurements", "RoscoController", "RoscoError", "read_discon",
           "CpTable", "Drivetrain", "RotorSimResult", "aerodynamic_torque", "euler_step", "simulate_like_rosco_sim",
           "WindSeries", "blade_height", "extreme_direction_change", "extreme_operating_gust", "kaimal", "read_wind",
           "shear", "steady", "step_change", "write_wind",
           "Blade", "BladeAero", "Polar", "RotorGeometry", "bem_loads", "node_heights", "read_polar",
           "BladeMass", "RootLoads", "bearing_inputs", "bearing_load_series", "root_loads",
           "TurbineConfig", "TurbineResult", "run_turbine"]
