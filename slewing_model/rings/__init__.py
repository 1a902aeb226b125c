"""Ring flexibility: the rings' condensed stiffness and what the solver makes of it.

Paper section 2.2 (eqs 12-16). Run time, numpy only, except :mod:`.superelement`, which builds the
stiffness with scikit-fem at build time and is not imported here.

* :mod:`.stiffness` -- the superelement as stored (:class:`Superelement`, its cache key);
* :mod:`.compliance` -- its block-circulant inverse, the groove displacements;
* :mod:`.reduced_operator` -- the inverse operator of the flexible Newton step and its updates;
* :mod:`.superelement` -- build time: the scikit-fem ring model condensed to the groove centres.
"""
from .stiffness import RingStiffness, Superelement, SuperelementMismatchError

__all__ = ["RingStiffness", "Superelement", "SuperelementMismatchError"]
