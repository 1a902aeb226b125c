"""FMI 2.0 co-simulation slave of a time table: signals against time (pythonfmu).

The signal sources of the pitch system SSP (``examples/ssp/``): the blade-root
load series (linear interpolation, as :meth:`slewing_drives.LoadSeries.at`)
and the pitch angle command (a step table, held from each break point on).
The table is ``table.json`` in the FMU's resources::

    {"name": ..., "interpolation": "linear" | "previous", "time": [...],
     "columns": [[name, unit, description], ...], "values": [[row], ...]}

Outputs are the table's values at the end of each communication step (at
the start time after initialisation), held constant outside the table. The
time is rounded to 1 ns before the look-up, so that a host that adds up its
step sizes in floating point (0.01 added 600 times is 5.9999999999999...)
hits a break point of a step table where it lies (6.0).
"""
from __future__ import annotations

import bisect
import json
import os
from xml.etree.ElementTree import Element, SubElement

import numpy as np
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Initial

#: SI units a table may use: name -> exponents of (kg, m, s, rad)
UNITS = {"N": (1, 1, -2, 0), "N.m": (1, 2, -2, 0), "rad": (0, 0, 0, 1), "rad/s": (0, 0, -1, 1), "m": (0, 1, 0, 0),
         "s": (0, 0, 1, 0), "1": (0, 0, 0, 0)}


class TimeTable(Fmi2Slave):
    author = "slewing_drives"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        resources = self.resources or os.path.dirname(os.path.abspath(__file__))
        with open(os.path.join(resources, "table.json")) as fh:
            table = json.load(fh)
        self.modelName = "TimeTable"
        self.description = f"time table: {table['name']} ({table['interpolation']} interpolation)"
        self.default_experiment = DefaultExperiment(start_time=0.0, stop_time=float(table["time"][-1]), step_size=0.01)
        self._time = np.asarray(table["time"], dtype=float)
        self._values = np.asarray(table["values"], dtype=float).reshape(len(self._time), len(table["columns"]))
        self._linear = table["interpolation"] == "linear"
        self._units = {}
        self._names = []
        for name, unit, text in table["columns"]:
            setattr(self, name, 0.0)
            self._units[name] = unit
            self._names.append(name)
            self.register_variable(Real(name, causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                                        initial=Fmi2Initial.calculated, description=text), nested=False)
        self._evaluate(0.0)

    def to_xml(self, model_options=dict()) -> Element:
        """pythonfmu's model description plus units and the (empty) dependencies of the outputs."""
        root = super().to_xml(model_options)
        definitions = Element("UnitDefinitions")
        for name in sorted(set(self._units.values())):
            unit = SubElement(definitions, "Unit", name=name)
            SubElement(unit, "BaseUnit", {k: str(v) for k, v in zip(("kg", "m", "s", "rad"), UNITS[name]) if v})
        root.insert(list(root).index(root.find("CoSimulation")) + 1, definitions)
        index = {}
        for i, sv in enumerate(root.find("ModelVariables"), start=1):
            index[sv.get("name")] = i
            sv.find("Real").set("unit", self._units[sv.get("name")])
        structure = root.find("ModelStructure")
        for child in list(structure):
            structure.remove(child)
        outputs, initial = SubElement(structure, "Outputs"), SubElement(structure, "InitialUnknowns")
        for name in self._names:
            SubElement(outputs, "Unknown", index=str(index[name]), dependencies="")
            SubElement(initial, "Unknown", index=str(index[name]), dependencies="")
        return root

    def setup_experiment(self, start_time, stop_time, tolerance):
        self._evaluate(start_time)

    def do_step(self, current_time: float, step_size: float) -> bool:
        self._evaluate(current_time + step_size)
        return True

    def _evaluate(self, t: float) -> None:
        t = round(t * 1e9) / 1e9
        if self._linear:
            row = [np.interp(t, self._time, self._values[:, k]) for k in range(len(self._names))]
        else:
            row = self._values[max(bisect.bisect_right(self._time.tolist(), t) - 1, 0)]
        for name, value in zip(self._names, row):
            setattr(self, name, float(value))
