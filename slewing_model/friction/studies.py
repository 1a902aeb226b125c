"""Friction torque studies: over a turn of the ring (torque ripple) and against preload
(the paper's Fig. 14).

Run-time module: numpy and the standard library (a superelement is built with scipy and
scikit-fem when a flexible study is not given one).
"""
from __future__ import annotations

import numpy as np

from . import torque as friction_model
from .contact import DEFAULT_MU
from .ellipse_quadrature import DEFAULT_QUADRATURE
from ..bearing.geometry import Bearing


def torque_ripple(bearing: Bearing, loads, psi, *, model: str = "rigid", superelement=None, mu: float = DEFAULT_MU,
                  cage_angle=None, loads_frame: str = "fixed", seal_torque: float = 0.0,
                  seal_torque_per_length: float = 0.0, quadrature=DEFAULT_QUADRATURE, bc: str = "free",
                  mesh: str = "coarse", rtol: float = 1e-8, details: bool = False):
    """Friction torque magnitude (N m) at each rotation ``psi`` of the moving ring.

    At every ``psi`` the bearing is re-assembled (each ring's errors read under
    the balls at that rotation, :mod:`slewing_model.distribution.assembly`), the load
    distribution solved with a warm-started :class:`~slewing_model.distribution.bime.BimeSolver`
    (``set_rotation``) and the friction computed with a warm-started ball
    equilibrium. The configuration repeats when ``psi`` changes by ``2 pi`` at
    the same cage angle and, without ball-diameter errors, when the cage angle
    changes by one ball pitch ``2 pi / B``.

    Parameters
    ----------
    bearing : Bearing
    loads : Loads or None
        On the moving ring.
    psi : array_like, rad
        Rotations of the moving ring.
    model : {"rigid", "flexible"}
    superelement : Superelement, optional
        For ``model="flexible"`` (built with ``bc`` and ``mesh`` when not given).
    mu : float
    cage_angle : array_like, rad, optional
        Rotation of the ball set at each ``psi``; default: rolling without slip
        (:func:`slewing_model.distribution.assembly.cage_ratio`).
    loads_frame : {"fixed", "moving"}
        Frame in which ``loads`` stays constant: ``"moving"`` turns it with the
        moving ring (e.g. the blade loads on a pitch bearing).
    seal_torque, seal_torque_per_length : float
        As in :func:`~slewing_model.friction.friction_torque`.
    quadrature : int or (int, int)
    bc, mesh : str
        Superelement options when it is built here.
    rtol : float
        Force tolerance of the BIME solves (1e-8 is ample for the torque; the
        BIME default 1e-10 sits at the round-off floor of some cases).
    details : bool
        Also return the lists of load distributions and :class:`~slewing_model.friction.FrictionTorque`.

    Returns
    -------
    ndarray, N m, shape of ``psi``
        (and, with ``details``, the distributions and friction results).
    """
    from ..distribution.bime import BimeSolver, Loads

    if model not in ("rigid", "flexible"):
        raise ValueError(f"model = {model!r}: must be 'rigid' or 'flexible'")
    if loads_frame not in ("fixed", "moving"):
        raise ValueError(f"loads_frame = {loads_frame!r}: must be 'fixed' or 'moving'")
    loads = Loads() if loads is None else loads
    psi = np.asarray(psi, dtype=float)
    flat = psi.ravel()
    cages = None if cage_angle is None else np.broadcast_to(np.asarray(cage_angle, dtype=float), psi.shape).ravel()
    if model == "flexible" and superelement is None:
        from ..rings.superelement import build_superelement

        superelement = build_superelement(bearing, mesh=mesh, bc=bc)
    solver = BimeSolver(bearing, superelement if model == "flexible" else None,
                        psi=float(flat[0]) if flat.size else 0.0,
                        cage_angle=None if cages is None else float(cages[0]), rtol=rtol)
    out = np.empty(flat.size)
    distributions, frictions = [], []
    distribution = friction = None
    for k, angle in enumerate(flat):
        solver.set_rotation(float(angle), None if cages is None else float(cages[k]))
        load_k = loads.rotated(float(angle)) if loads_frame == "moving" else loads
        distribution = solver.solve(load_k, initial=distribution)
        friction = friction_model.friction_torque(bearing, distribution, mu=mu, seal_torque=seal_torque,
                                   seal_torque_per_length=seal_torque_per_length, quadrature=quadrature,
                                   initial=friction)
        out[k] = friction.magnitude
        if details:
            distributions.append(distribution)
            frictions.append(friction)
    out = out.reshape(psi.shape)
    return (out, distributions, frictions) if details else out


def preload_sweep(bearing: Bearing, preloads, loads=None, *, model: str = "rigid", superelement=None,
                  mu: float = DEFAULT_MU, psi: float = 0.0, quadrature=DEFAULT_QUADRATURE, rtol: float = 1e-8,
                  details: bool = False):
    """Friction torque magnitude (N m) against ball preload (m), as the paper's Figure 14.

    Parameters
    ----------
    bearing : Bearing
    preloads : array_like, m
        Ball oversize values (``Bearing.with_preload``).
    loads : Loads, optional
        External load (None: idling, as Figure 14).
    model : {"rigid", "flexible"}
    superelement : Superelement, optional
        For the flexible model; the ring matrices do not depend on the preload.
    mu, psi, quadrature, rtol
        As in :func:`~slewing_model.friction.friction_torque` and :func:`slewing_model.distribution.bime.solve`.
    details : bool
        Also return the list of :class:`~slewing_model.friction.FrictionTorque` (contact counts etc.).
    """
    from ..distribution.bime import solve

    preloads = np.asarray(preloads, dtype=float)
    out = np.empty(preloads.size)
    results = []
    friction = None
    for k, preload in enumerate(preloads.ravel()):
        b = bearing.with_preload(float(preload))
        distribution = solve(b, loads, model=model, superelement=superelement, psi=psi, rtol=rtol)
        friction = friction_model.friction_torque(b, distribution, mu=mu, quadrature=quadrature, initial=friction)
        out[k] = friction.magnitude
        results.append(friction)
    out = out.reshape(preloads.shape)
    return (out, results) if details else out
