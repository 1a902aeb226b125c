"""The bearing: its geometry, its manufacturing errors and the Hertz contact of a ball.

Paper section 2.1 (Figure 2, eqs 8-11). Run time, numpy only.

* :mod:`.conventions` -- contact numbering, the bearing file's tables and their error;
* :mod:`.geometry` -- :class:`Bearing`, the definition file (:func:`load_bearing`);
* :mod:`.manufacturing` -- measured or synthetic raceway and ball errors;
* :mod:`.contact` -- Houpert's stiffness, the Hertz ellipse and pressure.
"""
from .conventions import BearingDefinitionError
from .geometry import Bearing, RingSection, bearing_from_dict, load_bearing
from .manufacturing import ManufacturingErrors, RingErrorMap, synthetic_errors

__all__ = ["Bearing", "BearingDefinitionError", "ManufacturingErrors", "RingErrorMap", "RingSection",
           "bearing_from_dict", "load_bearing", "synthetic_errors"]
