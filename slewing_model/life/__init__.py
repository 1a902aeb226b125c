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
"""
from .rating import (LifeInputError, Raceway, RacewayLife, axial_rating, combined_life, equivalent_load,
                     four_point_capacities, iso281_axial_rating, raceway_capacity, raceway_life,
                     radial_bearing_life, radial_raceway_capacities)
from .oscillation import critical_angle, dg03_rating_factor, equivalent_revolutions, rainflow_cycles
from .raceway_map import RacewayMap, default_slices, track_damage
from .wear import rolling_travel, relubrication_gap
from .dg03 import DG03Life, dg03_life, equivalent_axial_load
from .duty import LifeAccumulator, LifeModel, LifeResult, LifeSettings, analyse_run

__all__ = [
    "LifeInputError", "Raceway", "RacewayLife", "axial_rating", "combined_life", "equivalent_load",
    "four_point_capacities", "iso281_axial_rating", "raceway_capacity", "raceway_life", "radial_bearing_life",
    "radial_raceway_capacities",
    "critical_angle", "dg03_rating_factor", "equivalent_revolutions", "rainflow_cycles",
    "RacewayMap", "default_slices", "track_damage", "rolling_travel", "relubrication_gap",
    "DG03Life", "dg03_life", "equivalent_axial_load",
    "LifeAccumulator", "LifeModel", "LifeResult", "LifeSettings", "analyse_run",
]
