"""A wind turbine around the pitch and yaw bearings: ROSCO's controller, rotor, wind, blade loads.

* :mod:`slewing_turbine.controller` -- ROSCO (NREL's controller library) called in process
* :mod:`slewing_turbine.rotor` -- rigid drivetrain, rotor performance table, ROSCO's simulator loop
"""
from .controller import Commands, Measurements, RoscoController, RoscoError, read_discon
from .rotor import CpTable, Drivetrain, RotorSimResult, aerodynamic_torque, euler_step, simulate_like_rosco_sim

__all__ = ["Commands", "Measurements", "RoscoController", "RoscoError", "read_discon",
           "CpTable", "Drivetrain", "RotorSimResult", "aerodynamic_torque", "euler_step", "simulate_like_rosco_sim"]
