"""Numerics the models share: the numba compile registry and the BLAS thread limit.

* :mod:`.compiled` -- whether numba runs the loops, and how a kernel module enters them;
* :mod:`.blas` -- BLAS threads held to one inside a step.
"""
