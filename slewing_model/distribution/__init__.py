"""The load distribution: Rigid-BIME and Flexible-BIME.

Paper sections 2.1-2.3 (eqs 1, 16-23). Run time, numpy only.

* :mod:`.results` -- the loads (:class:`Loads`) and the answer (:class:`LoadDistribution`);
* :mod:`.assembly` -- the contact springs of every ball, errors and preload included;
* :mod:`.bime` -- the energy, its Newton solver, :func:`solve`;
* :mod:`.kernel` -- the solver's per-contact loops, compiled with numba where it is installed.
"""
from .bime import BimeSolver, solve
from .results import LOAD_FIELDS, LoadCapacityError, LoadDistribution, Loads, NoEquilibriumError

__all__ = ["BimeSolver", "LOAD_FIELDS", "LoadCapacityError", "LoadDistribution", "Loads", "NoEquilibriumError",
           "solve"]
