"""Four-point contact slewing bearing: load distribution and friction torque.

The method is that of Heras et al., *Load distribution and friction torque in
four-point contact slewing bearings considering manufacturing errors and ring
flexibility* (the theory section follows it equation by equation): Hertz contact springs between groove
centres (Rigid-BIME), ring flexibility through a precomputed finite element
superelement (Flexible-BIME), and an analytical friction torque fed by the load
distribution.

The run-time part of this package imports numpy only; building a superelement
(:mod:`slewing_model.rings.superelement`) needs scipy and scikit-fem.
"""
from .bearing.geometry import Bearing, BearingDefinitionError, RingSection, load_bearing, bearing_from_dict
from .bearing.manufacturing import ManufacturingErrors, RingErrorMap, synthetic_errors
from .distribution.bime import BimeSolver, LoadCapacityError, LoadDistribution, Loads, NoEquilibriumError, solve
from .friction.torque import FrictionTorque, catalogue_torque, friction_torque

__version__ = "1.1.0"

#: the run-time part of the package (numpy and the standard library): the modules an FMU carries
#: (paths below slewing_model/, without .py; build_fmu.py keeps each subpackage's folder). Not in it:
#: rings/superelement (scikit-fem, build time), study, loads, cli, plots and life/command (host side)
RUNTIME_MODULES = ("__init__",
                   "bearing/__init__", "bearing/conventions", "bearing/geometry", "bearing/manufacturing",
                   "bearing/contact", "bearing/connection",
                   "rings/__init__", "rings/stiffness", "rings/compliance", "rings/reduced_operator",
                   "distribution/__init__", "distribution/results", "distribution/assembly", "distribution/kernel",
                   "distribution/bime",
                   "friction/__init__", "friction/ellipse_quadrature", "friction/contact", "friction/ball_kinematics",
                   "friction/kernel", "friction/catalogue", "friction/torque", "friction/studies",
                   "numerics/__init__", "numerics/compiled", "numerics/blas", "numerics/targets",
                   "simulation/__init__", "simulation/simulator",
                   # rainflow is imported only by the life post-processing
                   "life/__init__", "life/rating", "life/oscillation", "life/raceway_map", "life/kernel", "life/wear",
                   "life/dg03",
                   "life/duty")

__all__ = [
    "Bearing", "BearingDefinitionError", "RingSection", "load_bearing", "bearing_from_dict",
    "ManufacturingErrors", "RingErrorMap", "synthetic_errors",
    "BimeSolver", "LoadCapacityError", "LoadDistribution", "Loads", "NoEquilibriumError", "solve",
    "FrictionTorque", "catalogue_torque", "friction_torque",
    "__version__", "RUNTIME_MODULES",
]
