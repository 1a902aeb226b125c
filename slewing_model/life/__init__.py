"""Life and wear of oscillating pitch and yaw bearings, from the load on every ball.

* :mod:`.rating` -- ISO/TS 16281 raceway capacities ``Qc``, equivalent loads ``Qe`` and the
  combined L10 of any ball bearing's raceways; ISO 281's axial rating of the four-point bearing.
* :mod:`.oscillation` -- rainflow cycles of the ring angle, critical angle, DG03's factor,
  Miner's rule.
* :mod:`.raceway_map` -- damage of each track slice by slice, from the balls that roll over it.
* :mod:`.wear` -- rolling travel ``x`` against the Hertz patch ``2b``, relubrication gaps.
* :mod:`.dg03` -- NREL DG03's catalogue life of the same run.
* :mod:`.duty` -- the step-by-step accumulator (FMU, studies) and a run's analysis.

The method, its sources and its checks are on the user guide's life and wear page.
Run-time part: numpy only (``rainflow`` is imported by the cycle counting of a finished run).

The names below are imported from their modules when first asked for (``from slewing_model.life import
LifeAccumulator``; PEP 562): the contact loops import :mod:`.kernel` alone, and a run without the life
accumulators imports nothing else of this package.
"""
from importlib import import_module as _import_module

#: the names this package exports, by the module that defines them
_MODULES = {
    "rating": ("LifeInputError", "Raceway", "RacewayLife", "axial_rating", "combined_life", "equivalent_load",
               "four_point_capacities", "iso281_axial_rating", "raceway_capacity", "raceway_life",
               "radial_bearing_life", "radial_raceway_capacities"),
    "oscillation": ("critical_angle", "dg03_rating_factor", "equivalent_revolutions", "rainflow_cycles"),
    "raceway_map": ("RacewayMap", "default_slices", "track_damage"),
    "wear": ("rolling_travel", "relubrication_gap"),
    "dg03": ("DG03Life", "dg03_life", "equivalent_axial_load"),
    "duty": ("LifeAccumulator", "LifeModel", "LifeResult", "LifeSettings", "analyse_run"),
}
_LAZY = {name: module for module, names in _MODULES.items() for name in names}


def __getattr__(name):
    if name in _LAZY:
        value = getattr(_import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    if name in _MODULES:                 # a module of the package, as an attribute (slewing_model.life.duty)
        return _import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted((set(globals()) - {"_LAZY", "_MODULES", "_import_module"}) | set(_LAZY) | set(_MODULES))


__all__ = [
    "LifeInputError", "Raceway", "RacewayLife", "axial_rating", "combined_life", "equivalent_load",
    "four_point_capacities", "iso281_axial_rating", "raceway_capacity", "raceway_life", "radial_bearing_life",
    "radial_raceway_capacities",
    "critical_angle", "dg03_rating_factor", "equivalent_revolutions", "rainflow_cycles",
    "RacewayMap", "default_slices", "track_damage", "rolling_travel", "relubrication_gap",
    "DG03Life", "dg03_life", "equivalent_axial_load",
    "LifeAccumulator", "LifeModel", "LifeResult", "LifeSettings", "analyse_run",
]
