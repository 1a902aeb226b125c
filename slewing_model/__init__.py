"""Four-point contact slewing bearing: load distribution and friction torque.

The method is that of Heras et al., *Load distribution and friction torque in
four-point contact slewing bearings considering manufacturing errors and ring
flexibility* (``shared/reference``): Hertz contact springs between groove
centres (Rigid-BIME), ring flexibility through a precomputed finite element
superelement (Flexible-BIME), and an analytical friction torque fed by the load
distribution.

The run-time part of this package imports numpy only; building a superelement
(:mod:`slewing_model.superelement`) needs scipy and scikit-fem.
"""
from .geometry import Bearing, BearingDefinitionError, RingSection, load_bearing, bearing_from_dict
from .errors import ManufacturingErrors, RingErrorMap, synthetic_errors
from .bime import BimeSolver, LoadCapacityError, LoadDistribution, Loads, NoEquilibriumError, solve
from .friction import FrictionTorque, catalogue_torque, friction_torque

__version__ = "0.1.0"

#: the run-time part of the package (numpy and the standard library): the modules an FMU carries
#: (paths below slewing_model/, without .py)
RUNTIME_MODULES = ("__init__", "geometry", "errors", "contact", "contact_kernel", "assembly", "distribution",
                   "ring_stiffness", "ring_compliance", "reduced_operator", "bime", "blas", "ellipse_quadrature",
                   "contact_friction", "ball_kinematics", "friction_kernel", "catalogue", "friction_studies",
                   "friction", "simulator",
                   # the life subpackage's run-time modules (build_fmu copies them into the FMU's
                   # slewing_model/life; rainflow is imported only by the post-processing)
                   "life/__init__", "life/rating", "life/oscillation", "life/raceway_map", "life/wear", "life/dg03",
                   "life/duty")

__all__ = [
    "Bearing", "BearingDefinitionError", "RingSection", "load_bearing", "bearing_from_dict",
    "ManufacturingErrors", "RingErrorMap", "synthetic_errors",
    "BimeSolver", "LoadCapacityError", "LoadDistribution", "Loads", "NoEquilibriumError", "solve",
    "FrictionTorque", "catalogue_torque", "friction_torque",
    "__version__", "RUNTIME_MODULES",
]
