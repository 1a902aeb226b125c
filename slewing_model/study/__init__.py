"""Studies of many cases: load series x bearing variants, run on Dask distributed.

Not part of the FMU's run time (it imports dask); it runs the same
:class:`slewing_model.simulation.simulator.BearingSimulator` the FMU runs, once per case.

* :mod:`.definition` -- the study file (TOML): validation, expansion into cases, case keys;
* :mod:`.series` -- load series with the ring's motion (our CSV, OpenFAST files, constant);
* :mod:`.case` -- one case: stepping, statistics, per-ball load spectrum;
* :mod:`.engine` -- the Dask run, skipping finished cases, the output directory;
* :mod:`.figures` -- the figures of a study;
* :mod:`.command` -- ``slewing batch STUDY.toml -o DIR [--workers N] [--scheduler ADDRESS]``.
"""
from .case import CaseResult, CaseTask, run_case
from .definition import Case, Study, StudyDefinitionError, load_study, study_from_dict
from .engine import ForeignOutputError, StudyInterrupted, StudyReport, run_study
from .series import MotionSeries

__all__ = ["Case", "CaseResult", "CaseTask", "ForeignOutputError", "MotionSeries", "Study", "StudyDefinitionError",
           "StudyInterrupted", "StudyReport",
           "load_study", "run_case", "run_study", "study_from_dict"]
