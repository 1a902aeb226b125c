"""Boundary conditions of a ring, per harmonic.

* ``free`` -- no support, as in the paper's idling model. The rigid-body modes
  have no stiffness: X, Y (translation), Z, rx, ry (tilts). They are removed
  from the FE solves with Lagrange constraints (n = 0: Z; n = 1: X and the tilt)
  and from the condensed matrix exactly (:func:`condense.rigid_master_modes`):
  its null space is spanned by the five patterns.
  Rotation about z (rz) moves no master DOF (they have no circumferential
  component) and is not in the model.
* ``clamped`` -- the bolted face (``RingSection.bolted_face``) has all three
  displacements zero: all rigid modes are removed by the support; the
  condensed matrix is positive definite.
* ``frictionless`` -- the bolted face rests on a rigid, frictionless plane:
  its axial displacement is zero (removes Z, rx, ry) and it may slide and
  deform in its plane. The bolts keep the ring centred: the *mean* in-plane
  translation of the bolted face is zero (one constraint at n = 1, removes X
  and Y); locally the face still slides freely. The condensed matrix is
  positive definite.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skfem import FacetBasis, LinearForm, asm

from .harmonic import HarmonicRingModel

BOUNDARY_CONDITIONS = ("free", "clamped", "frictionless")

#: rigid-body modes of the condensed matrix (its null space) per boundary condition
NULL_SPACE = {"free": ("X", "Y", "Z", "rx", "ry"), "clamped": (), "frictionless": ()}

#: what the support itself takes out, for the metadata
SUPPORT_REMOVES = {
    "free": "nothing: the five rigid-body modes X, Y, Z, rx, ry are the exact null space of the matrix",
    "clamped": "X, Y, Z, rx, ry (and rz): all displacements of the bolted face are zero",
    "frictionless": "Z, rx, ry by the axial support of the bolted face; X, Y by the bolts "
                    "(zero mean in-plane translation of the bolted face); the face slides freely otherwise",
}


@dataclass
class Support:
    """Fixed DOFs and constraints of one boundary condition on one ring model."""

    kind: str
    model: HarmonicRingModel
    bolted_facets: np.ndarray

    def __post_init__(self):
        if self.kind not in BOUNDARY_CONDITIONS:
            raise ValueError(f"boundary condition {self.kind!r}: must be one of {', '.join(BOUNDARY_CONDITIONS)}")
        m = self.model
        if self.kind == "clamped":
            self._fixed = m.facet_dofs(self.bolted_facets, (0, 1, 2))
        elif self.kind == "frictionless":
            self._fixed = m.facet_dofs(self.bolted_facets, (2,))
            fb = FacetBasis(m.mesh, m.element, facets=self.bolted_facets, intorder=4)

            @LinearForm
            def mean_translation(v, w):       # int (U - V) r ds: in-plane x-translation at n = 1
                return (v[0] - v[1]) * w.x[0]

            self._centring = asm(mean_translation, fb)[:, None]
        else:
            self._fixed = np.zeros(0, dtype=int)

    @property
    def free(self) -> bool:
        return self.kind == "free"

    def fixed(self, n: int) -> np.ndarray:
        return self._fixed

    def constraints(self, n: int):
        if self.kind == "free":
            return self.model.rigid_modes(n) if n <= 1 else None
        if self.kind == "frictionless" and n == 1:
            return self._centring
        return None
