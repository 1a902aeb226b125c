"""The raceway damage map's step as one compiled loop (numba, where it is installed).

:meth:`slewing_model.life.raceway_map.RacewayMap.update` adds the passes of the balls between two
steps to the slices they crossed: with numpy some thirty array operations a step (the crossed
slices of each ring, ``np.unique``, a ``bincount`` per track), each a few microseconds of call
overhead for a few dozen passes. :func:`_map_update` is the same sum as one loop over tracks,
balls and the slices each ball crossed, in place, with the step's ``Q^3``. It adds the passes one by
one where numpy sums a slice's passes first: the map and its sums agree to round-off
(``tests/test_life.py``). :func:`_widest_contacts` finds each track's widest contact patch, which
``LifeAccumulator.step`` took with numpy's ``argmax`` and fancy indexing (16 us of a step).
"""
from __future__ import annotations

import math

import numpy as np

from ..numerics.compiled import compile_loop, loop_factory

_MAP_UPDATE_SIGNATURE = "f8[:, :](f8[:, :], f8[:], f8[:], b1[:], f8[:], f8[:], f8, f8, f8[:, :], f8[:, :], f8)"


def _map_update(damage_map, power, scale, moving, angle_old, angle_new, psi_old, psi_new, q3_old, contact_load, slope):
    """Add the passes from the last step to this one to ``damage_map`` (4, N) and to each track's
    ``power`` (4,) ``Σ_j d_j^slope``, in place: ball ``b`` passes the slices whose centres lie between
    its old and new place on the track's ring (``angle - psi`` on the moving ring, ``moving`` (4,)),
    half-open, each pass carrying ``scale[k] (q3_old[b, k] + q3_new[b, k]) / 2``
    (:func:`slewing_model.life.raceway_map.crossed_slices`, ``RacewayMap._add``). Returns ``q3_new``, the
    cubes of this step's ``contact_load`` (B, 4), negatives as zero (``RacewayMap.update``'s); with no
    last step (``angle_old`` empty) only that."""
    q3_new = np.empty(contact_load.shape)
    for b in range(contact_load.shape[0]):
        for k in range(contact_load.shape[1]):
            load = max(contact_load[b, k], 0.0)
            q3_new[b, k] = load ** 3.0             # pow, as numpy's ** 3
    slices = damage_map.shape[1]
    per_radian = slices / (2.0 * math.pi)
    for k in range(damage_map.shape[0]):
        shift_old = psi_old if moving[k] else 0.0
        shift_new = psi_new if moving[k] else 0.0
        for b in range(angle_old.size):
            u0 = (angle_old[b] - shift_old) * per_radian - 0.5
            u1 = (angle_new[b] - shift_new) * per_radian - 0.5
            first = math.floor(min(u0, u1))
            count = int(math.floor(max(u0, u1)) - first)
            if count == 0:
                continue
            mean = 0.5 * (q3_new[b, k] + q3_old[b, k]) * scale[k]
            for j in range(count):
                s = int((first + 1 + j) % slices)
                old = damage_map[k, s]
                new = old + mean
                power[k] += new ** slope - old ** slope
                damage_map[k, s] = new
    return q3_new


_WIDEST_SIGNATURE = "UniTuple(f8[:], 2)(f8[:, :], f8[:, :])"


def _widest_contacts(semi_b, contact_angle):
    """The widest contact patch of each track this step: the largest ``semi_b`` of each column (4,) and
    the ``contact_angle`` at it (the first ball of the largest, as ``np.argmax``; ``LifeAccumulator.step``)."""
    n_balls, n_tracks = semi_b.shape
    widest, angle = np.empty(n_tracks), np.empty(n_tracks)
    for k in range(n_tracks):
        best = 0
        for b in range(1, n_balls):
            if semi_b[b, k] > semi_b[best, k]:
                best = b
        widest[k], angle[k] = semi_b[best, k], contact_angle[best, k]
    return widest, angle


#: the helpers the loops call
_HELPERS: tuple = ()
#: numba's error model of these loops (Python's: a division by zero raises)
ERROR_MODEL = "python"


def _compile(function, signature):
    return compile_loop(function, signature, _HELPERS, error_model=ERROR_MODEL)


#: (factory, Python function) of each compiled loop of the life model
KERNELS: list = []
compiled_map_update = loop_factory(KERNELS, _compile, _map_update, _MAP_UPDATE_SIGNATURE)
compiled_widest_contacts = loop_factory(KERNELS, _compile, _widest_contacts, _WIDEST_SIGNATURE)
