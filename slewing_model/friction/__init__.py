"""The friction torque, fed by the load distribution.

Paper section 3 (the analytical model its conclusion proposes). Run time, numpy only.

* :mod:`.contact` -- Coulomb traction over a contact ellipse;
* :mod:`.ellipse_quadrature` -- the quadrature over the ellipse;
* :mod:`.ball_kinematics` -- each ball's rotation from its own quasi-static equilibrium;
* :mod:`.torque` -- :func:`friction_torque`, the bearing's torque;
* :mod:`.catalogue` -- the catalogue formula, for comparison;
* :mod:`.studies` -- torque ripple over an angle, preload sweeps;
* :mod:`.kernel` -- the loops compiled with numba where it is installed.
"""
from .catalogue import CATALOGUE_MU, catalogue_torque
from .contact import DEFAULT_MU, EllipseFriction, conformity_radius, ellipse_friction
from .ellipse_quadrature import EllipseQuadrature, ellipse_quadrature
from .studies import preload_sweep, torque_ripple
from .torque import (FrictionTorque, friction_torque, omega_regularisation_for_step, regularised_torque,
                     stick_slip_torque)

__all__ = ["CATALOGUE_MU", "DEFAULT_MU", "EllipseFriction", "EllipseQuadrature", "FrictionTorque",
           "catalogue_torque", "conformity_radius", "ellipse_friction", "ellipse_quadrature", "friction_torque",
           "omega_regularisation_for_step", "preload_sweep", "regularised_torque", "stick_slip_torque",
           "torque_ripple"]
