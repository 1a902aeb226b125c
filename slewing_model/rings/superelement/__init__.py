"""Build-time ring superelement: scikit-fem model of each ring condensed to the groove centres.

Paper section 2.2, eqs 12-15. Needs scipy and scikit-fem (the
``build`` extra); the result is read at run time by
:mod:`slewing_model.rings.stiffness` with numpy only.

Modules, in the order of the computation:

* :mod:`.section` -- ring cross-section with the gothic-arch groove, structured mesh;
* :mod:`.harmonic` -- Fourier-harmonic axisymmetric FE model ``K(n) = K0 + n K1 + n^2 K2``;
* :mod:`.coupling` -- groove centre to raceway patch (distributing), half-space part;
* :mod:`.supports` -- free / clamped / frictionless;
* :mod:`.condense` -- aliasing to B balls, rigid modes, first block row;
* :mod:`.build` -- :func:`build_superelement` and its cache;
* :mod:`.command` -- the ``slewing superelement`` command.
"""
from ..stiffness import RingStiffness, Superelement, SuperelementMismatchError, bearing_hash
from .build import build_superelement, default_cache_dir

__all__ = ["build_superelement", "default_cache_dir", "RingStiffness", "Superelement",
           "SuperelementMismatchError", "bearing_hash"]
