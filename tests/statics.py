"""Statics of the moving ring, summed from a load distribution independently of the solver."""

import numpy as np


def load_on_moving_ring(bearing, result, groove_centres=None):
    """Forces and moments (Fx, Fy, Fz, Mx, My) that balance the contacts on the moving (inner) ring,
    summed from Q, the contact angles and the groove-centre positions (eq 23 statics, small
    displacements): the applied load at equilibrium.

    groove_centres : ndarray (B, 4, 2), optional
        (R, z) of the groove centres of contacts 1..4 per ball (``assemble(bearing, psi)``, with the
        manufacturing errors); default the nominal ones of the bearing.
    """
    n = bearing.ball_count
    centres = np.broadcast_to(bearing.groove_centres if groove_centres is None else groove_centres, (n, 4, 2))
    phi = result.ball_angle
    total = np.zeros(5)
    for diagonal, (inner_contact, zsign) in enumerate(((3, 1.0), (2, -1.0))):
        q, alpha = result.contact_load[:, diagonal], result.contact_angle[:, diagonal]
        fr, fz = -q * np.cos(alpha), -zsign * q * np.sin(alpha)   # outer ring on inner ring
        r, z = centres[:, inner_contact - 1, 0], centres[:, inner_contact - 1, 1]
        fx, fy = fr * np.cos(phi), fr * np.sin(phi)
        px, py = r * np.cos(phi), r * np.sin(phi)
        total += [fx.sum(), fy.sum(), fz.sum(), (py * fz - z * fy).sum(), (z * fx - px * fz).sum()]
    return -total  # the applied load balances the contact forces
