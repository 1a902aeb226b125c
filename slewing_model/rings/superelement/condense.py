"""Condensation of the harmonic ring model to the groove centres of B discrete balls.

Paper eqs 12-15. The steps, each a function below:

1. :func:`harmonic_compliances` -- per continuous harmonic n the 4x4 compliance
   of the master loads (:mod:`.coupling`), ``c_n = L^T K(n)^-1 L``, with the
   supports of the boundary condition.
2. :func:`ring_part` -- minus the flat half-space compliance of the same patch
   loads, ``c_n - c_n^HS`` (the Hertz springs hold that part); at long waves,
   where this removes more than each ball's own half-space compliance,
   :func:`halfspace_addback` gives the excess back. Projected per harmonic onto
   the positive semi-definite matrices, except the long waves that are given back:
   their projection waits for the give-back (step 4).
3. :func:`ball_blocks` -- the **aliasing sums**. A unit master force of ball
   ``b`` is the patch pressure times ``H(s - r phi_b)``; with
   ``h_n = H_hat(n / r)`` the ball-to-ball compliance is

       G(phi_b' - phi_b) = 1/(2 pi) sum_{n in Z} (h_n h_n^T o c_|n|) exp(i n (phi_b' - phi_b)),

   block circulant over the B equally spaced balls, with discrete Fourier
   blocks (``G_hat_j = sum_k G_k exp(2 pi i j k / B)``)

       G_hat_j = B/(2 pi) sum_{n = j mod B} h_n h_n^T o c_|n|,   n = j, j - B, j + B, j - 2B, ...

4. :func:`stiffness_blocks` -- on the complement of the rigid modes of ball
   harmonic j (free ring: Z for j = 0; X/Y translation and tilt for j = +-1),
   the compliance (ring part plus the given-back excess) is projected onto the
   positive semi-definite cone, once, the
   compliance floor is added, and it is inverted:
   ``K_hat_j = Q (Q^T G_hat_j Q + floor)^-1 Q^T``, whose null space is exactly the
   rigid modes.
5. :func:`first_row` -- ``C_k = 1/B sum_j K_hat_j exp(-2 pi i j k / B)``.

Why the projection and the floor (docs/theory/superelement.md): beyond a few times
``r / section`` harmonics the ring answers a patch load like a half-space, and
the concave groove slightly *stiffer* than the flat one Hertz assumes, so
``c_n - c_n^HS`` becomes a small negative number; next to a clamped face the
ring is stiffer than a half-space at every wave length (the material between
the groove and the fixed face is a layer on a rigid base). Such directions have
no compliance beyond Hertz's: they are given the floor, a small fraction of the
Hertz (half-space) compliance of the patch, which keeps the matrix finite and
well conditioned. The long waves whose half-space excess is given back are
projected once per ball harmonic, after the give-back (projecting them per
continuous harmonic first would give the excess back twice).
"""
from __future__ import annotations

import numpy as np

from . import coupling as cp


def rigid_master_modes(patches, j: int) -> np.ndarray:
    """Rigid-body master patterns (R_a, z_a, R_b, z_b) of a free ring in ball harmonic ``j``, (4, m).

    j = 0: axial translation Z (0, 1, 0, 1). j = +-1: translation (1, 0, 1, 0) (X with cos,
    Y with sin) and tilt (z_a, -R_a, z_b, -R_b) (about y with cos, about x with sin), from
    the nominal groove-centre coordinates. Other j: none."""
    if j == 0:
        return np.array([[0.0, 1.0, 0.0, 1.0]]).T
    if j == 1:
        (ra, za), (rb, zb) = patches[0].centre, patches[1].centre
        return np.array([[1.0, 0.0, 1.0, 0.0], [za, -ra, zb, -rb]]).T
    return np.zeros((4, 0))


def harmonic_compliances(model, loads: np.ndarray, harmonics, support, progress=None) -> np.ndarray:
    """FE compliance ``c_n = L^T K(n)^-1 L`` of harmonics ``harmonics``, shape (len, 4, 4).

    Parameters
    ----------
    model : HarmonicRingModel
    loads : (ndofs, 4)
        Master load vectors (:func:`coupling.master_loads`).
    harmonics : iterable of int
    support : Support
        Fixed DOFs and constraints per harmonic (:mod:`.supports`).
    progress : callable or None
        Called with 1 after each harmonic (a progress bar's ``update``).
    """
    out = []
    for n in harmonics:
        solve = model.solver(n, fixed=support.fixed(n), constraints=support.constraints(n))
        out.append(loads.T @ solve(loads))
        if progress is not None:
            progress(1)
    c = np.array(out)
    return 0.5 * (c + c.transpose(0, 2, 1))


def halfspace_blocks(patches, lams, harmonics, youngs_modulus, poisson_ratio) -> np.ndarray:
    """Flat half-space compliance per harmonic in master DOFs, (len, 4, 4): the two
    same-patch 2x2 blocks ``Lam^T diag(c_n^HS) Lam``, zero between patches. n = 0 (where the
    2-D half-space compliance diverges logarithmically) takes the value of n = 1."""
    ns = np.maximum(np.asarray(list(harmonics)), 1)
    out = np.zeros((len(ns), 4, 4))
    for k, (patch, lam) in enumerate(zip(patches, lams)):
        c = cp.halfspace_harmonic(patch, ns, youngs_modulus, poisson_ratio)     # (len, 2)
        out[:, 2 * k:2 * k + 2, 2 * k:2 * k + 2] = np.einsum("ia,ni,ib->nab", lam, c, lam)
    return out


def halfspace_periodic(patch, ball_count: int, youngs_modulus: float, poisson_ratio: float) -> np.ndarray:
    """Ball-harmonic blocks of the half-space compliance of a whole row of B patches, in the
    basis (lambda_0, lambda_1): ``(B/2pi) sum_{n = +-j mod B} h_n^2 c_n^HS``, shape (B, 2), with
    the same n = 0 stand-in (the n = 1 value) as :func:`halfspace_blocks`. Harmonics up to
    40 r/b (where h_n^2 has decayed below 1e-6), interpolated log-log between 200 exact values."""
    n_max = int(40 * patch.radius / patch.b) + 2 * ball_count
    samples = np.unique(np.round(np.geomspace(1, n_max, 200)))
    c_s = cp.halfspace_harmonic(patch, samples, youngs_modulus, poisson_ratio)
    n = np.arange(n_max + 1)
    c = np.stack([np.exp(np.interp(np.log(np.maximum(n, 1)), np.log(samples), np.log(c_s[:, i])))
                  for i in range(2)], axis=1)
    cw = c * patch.circumferential_factor(n)[:, None] ** 2
    g = np.zeros((ball_count, 2))
    np.add.at(g, n % ball_count, cw)
    np.add.at(g, (-n[1:]) % ball_count, cw[1:])
    return g * ball_count / (2 * np.pi)


def halfspace_addback(patches, lams, ball_count: int, youngs_modulus: float, poisson_ratio: float) -> np.ndarray:
    """What the per-harmonic subtraction removes beyond each ball's own half-space compliance,
    (B, 4, 4) in master DOFs, to be added back to the ring compliance blocks.

    Removing ``c_n^HS`` harmonic by harmonic removes the half-space compliance of the whole row
    of patches, ``G_hat_j^HS``. Hertz holds only each ball's own part, ``S`` (the mean of
    ``G_hat_j^HS`` over j). At long waves (j < ~B/6) the row's half-space compliance exceeds S
    (the 1/distance tails of the neighbours add up; at j = 0 it diverges): there the excess
    ``max(G_hat_j^HS - S, 0)`` is given back, so that what is removed is S. At short waves it is
    below S and stays removed (removing S there would leave a negative ring compliance)."""
    out = np.zeros((ball_count, 4, 4))
    for k, (patch, lam) in enumerate(zip(patches, lams)):
        g = halfspace_periodic(patch, ball_count, youngs_modulus, poisson_ratio)
        s = cp.halfspace_self(patch, youngs_modulus, poisson_ratio)
        excess = np.maximum(g - s[None, :], 0.0)
        out[:, 2 * k:2 * k + 2, 2 * k:2 * k + 2] = np.einsum("ia,ni,ib->nab", lam, excess, lam)
    return out


def halfspace_self_block(patches, lams, youngs_modulus, poisson_ratio) -> np.ndarray:
    """Half-space self-compliance of both patches (the ring side of Hertz), master DOFs, (4, 4)."""
    out = np.zeros((4, 4))
    for k, (patch, lam) in enumerate(zip(patches, lams)):
        s = cp.halfspace_self(patch, youngs_modulus, poisson_ratio)
        out[2 * k:2 * k + 2, 2 * k:2 * k + 2] = lam.T @ np.diag(s) @ lam
    return out


def ring_part(c_fe: np.ndarray, c_hs: np.ndarray, patches, free: bool,
              given_back=None) -> tuple[np.ndarray, dict]:
    """``P+(c_n - c_n^HS)``: the ring's compliance beyond the half-space (Hertz) part, projected
    per harmonic onto the positive semi-definite matrices (negative directions: the ring is
    stiffer there than the flat half-space Hertz assumes; they get no compliance) -- except the
    harmonics ``given_back`` (bool per n, default none), whose long-wave excess is given back per
    ball harmonic (:func:`halfspace_addback`, :func:`given_back_harmonics`): those stay as they are
    and are projected with the give-back, per ball harmonic (:func:`stiffness_blocks`).

    Why: at low n, ``c_n^HS`` is the compliance of a *row* of patches, which
    grows without bound as n -> 0 (n = 0 takes the value of n = 1) and exceeds what a finite ring
    holds, most of all next to a clamped face. Clipping that negative part here and then giving
    the excess back would give the same compliance back twice and soften the contacts next to a
    clamped face (docs/validation/calculix-tilting.md). At the other harmonics the negative
    directions are the concave groove's (slightly stiffer than the flat half-space); clipping them
    per harmonic keeps the sum over harmonics convergent in N.

    For a free ring, harmonics 0 and 1 are projected on the complement of their rigid modes
    (only that part is used). Returns the projected compliances and a report (number of
    clipped directions, the most negative eigenvalue relative to the largest FE one, and the
    number of harmonics left for the ball-harmonic projection)."""
    out = np.zeros_like(c_fe)
    keep = np.zeros(c_fe.shape[0], dtype=bool) if given_back is None else np.asarray(given_back, dtype=bool)
    clipped, worst = 0, 0.0
    for n in range(c_fe.shape[0]):
        r = rigid_master_modes(patches, n) if free and n <= 1 else np.zeros((4, 0))
        q = np.linalg.qr(r, mode="complete")[0][:, r.shape[1]:] if r.shape[1] else np.eye(4)
        w, v = np.linalg.eigh(q.T @ (c_fe[n] - c_hs[n]) @ q)
        scale = np.abs(np.linalg.eigvalsh(q.T @ c_fe[n] @ q)).max()
        worst = min(worst, float(w.min() / scale))
        u = q @ v
        if n < keep.size and keep[n]:
            out[n] = (u * w) @ u.T
        else:
            clipped += int(np.sum(w < 0))
            out[n] = (u * np.maximum(w, 0.0)) @ u.T
    return out, {"clipped": clipped, "directions": int(4 * c_fe.shape[0]), "most_negative": worst,
                 "given_back_unprojected": int(keep[:c_fe.shape[0]].sum())}


def given_back_harmonics(back: np.ndarray, n_max: int) -> np.ndarray:
    """Harmonics n = 0..n_max whose half-space excess :func:`halfspace_addback` gives back (``back``,
    (B, 4, 4)): the long waves n < B / 2 (each its own ball harmonic j = n) where the give-back is
    not zero. They are not projected before the give-back (:func:`ring_part`)."""
    back = np.asarray(back)
    out = np.zeros(n_max + 1, dtype=bool)
    if back.ndim != 3:
        return out
    B = back.shape[0]
    n = np.arange(min(n_max + 1, (B + 1) // 2))
    out[n] = np.abs(back[n]).max(axis=(1, 2)) > 0
    return out


def condensed_blocks(c_fe: np.ndarray, c_hs: np.ndarray, back, patches, ball_count: int, free: bool, floor):
    """Steps 2-4 on harmonics 0..len(c_fe)-1: ring part (not projected where given back), aliasing,
    the give-back ``back`` (B, 4, 4) or 0, projection, floor, inversion. Returns
    ``(K_hat, ring_part report, ball-harmonic report)``."""
    c, ring_report = ring_part(c_fe, c_hs, patches, free, given_back_harmonics(back, c_fe.shape[0] - 1))
    k_hat, report = stiffness_blocks(ball_blocks(c, patches, ball_count) + back, patches, free, floor)
    return k_hat, ring_report, report


def ball_blocks(c: np.ndarray, patches, ball_count: int) -> np.ndarray:
    """Aliasing sums ``G_hat_j`` (B, 4, 4) of per-harmonic compliances ``c`` (n = 0..N)."""
    B = ball_count
    n = np.arange(c.shape[0])
    h = np.stack([patches[0].circumferential_factor(n), patches[0].circumferential_factor(n),
                  patches[1].circumferential_factor(n), patches[1].circumferential_factor(n)], axis=1)
    cw = c * h[:, :, None] * h[:, None, :]
    g = np.zeros((B, 4, 4))
    np.add.at(g, n % B, cw)                 # n >= 0
    np.add.at(g, (-n[1:]) % B, cw[1:])      # n < 0 (same |n|)
    g *= B / (2 * np.pi)
    return 0.5 * (g + g.transpose(0, 2, 1))


def stiffness_blocks(g_hat: np.ndarray, patches, free: bool, floor: float):
    """Stiffness blocks ``K_hat_j`` (B, 4, 4) and a report of the projection.

    Parameters
    ----------
    g_hat : (B, 4, 4)
        Ring compliance blocks (may be slightly indefinite, see module docstring).
    free : bool
        Remove the rigid modes of a free ring (j = 0 and j = +-1).
    floor : float, (4,) or (4, 4) array, m/N
        Compliance added to every block (a series spring per ball, positive semi-definite).

    Returns
    -------
    k_hat : (B, 4, 4)
    report : dict
        ``clipped``: number of (j, direction) pairs whose compliance was below zero,
        ``min_eig``/``max_eig``: extreme eigenvalues of the compliance before projection, m/N.
    """
    B = g_hat.shape[0]
    floor = np.asarray(floor, dtype=float)
    floor_mat = floor if floor.ndim == 2 else np.diag(np.broadcast_to(floor, (4,)))
    k_hat = np.zeros_like(g_hat)
    clipped, eigs = 0, []
    for j in range(B):
        jj = min(j, B - j)
        r = rigid_master_modes(patches, jj) if free else np.zeros((4, 0))
        if r.shape[1]:
            q = np.linalg.qr(r, mode="complete")[0][:, r.shape[1]:]
        else:
            q = np.eye(4)
        w, v = np.linalg.eigh(q.T @ g_hat[j] @ q)
        eigs.append(w)
        clipped += int(np.sum(w < 0))
        g = (v * np.maximum(w, 0.0)) @ v.T + q.T @ floor_mat @ q
        k = q @ np.linalg.inv(g) @ q.T
        k_hat[j] = 0.5 * (k + k.T)
    eigs = np.concatenate(eigs)
    return k_hat, {"clipped": clipped, "directions": int(eigs.size),
                   "min_eig": float(eigs.min()), "max_eig": float(eigs.max())}


def first_row(k_hat: np.ndarray) -> np.ndarray:
    """``C_k = 1/B sum_j K_hat_j exp(-2 pi i j k / B)`` (real: K_hat_j = K_hat_{B-j} real symmetric)."""
    return np.real(np.fft.fft(k_hat, axis=0)) / k_hat.shape[0]
