"""The friction torque, fed by the load distribution.

Paper section 3 (the analytical model its conclusion proposes). Run time, numpy only.

* :mod:`.contact` -- Coulomb traction over a contact ellipse;
* :mod:`.ellipse_quadrature` -- the quadrature over the ellipse;
* :mod:`.ball_kinematics` -- each ball's rotation from its own quasi-static equilibrium;
* :mod:`.torque` -- :func:`friction_torque`, the bearing's torque;
* :mod:`.catalogue` -- the catalogue formula, for comparison;
* :mod:`.studies` -- torque ripple over an angle, preload sweeps;
* :mod:`.kernel` -- the loops compiled with numba where it is installed.

:mod:`.studies` is imported when one of its functions is first asked for (``from slewing_model.friction
import torque_ripple``): a step never uses it.
"""
from importlib import import_module as _import_module

from .catalogue import CATALOGUE_MU, catalogue_torque
from .contact import DEFAULT_MU, EllipseFriction, conformity_radius, ellipse_friction
from .ellipse_quadrature import EllipseQuadrature, ellipse_quadrature
from .torque import (FrictionTorque, friction_torque, omega_regularisation_for_step, regularised_torque,
                     stick_slip_torque)

#: names exported here whose module is imported when the name is first asked for (PEP 562)
_LAZY = {"preload_sweep": "studies", "torque_ripple": "studies"}


def __getattr__(name):
    if name in _LAZY:
        value = getattr(_import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    if name == "studies":                # the module, as an attribute (slewing_model.friction.studies)
        return _import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted((set(globals()) - {"_LAZY", "_import_module"}) | set(_LAZY) | {"studies"})

__all__ = ["CATALOGUE_MU", "DEFAULT_MU", "EllipseFriction", "EllipseQuadrature", "FrictionTorque",
           "catalogue_torque", "conformity_radius", "ellipse_friction", "ellipse_quadrature", "friction_torque",
           "omega_regularisation_for_step", "preload_sweep", "regularised_torque", "stick_slip_torque",
           "torque_ripple"]
