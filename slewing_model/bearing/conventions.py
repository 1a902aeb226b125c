"""The conventions of the whole package (``DESIGN.md``): contact numbering, and the tables of a
bearing definition file with the error its readers raise.

* Contact 1 = upper-outer, 3 = lower-inner (diagonal 1, loaded when the inner ring is pushed
  towards +z); 4 = lower-outer, 2 = upper-inner (diagonal 2). The outer ring owns contacts 1
  and 4, the inner ring 2 and 3.
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np

#: contact numbers in array order: column ``i`` of every (B, 4) array is contact ``i + 1``
CONTACTS = (1, 2, 3, 4)
#: the two diagonals as (outer-ring contact, inner-ring contact), 1-based
DIAGONALS = ((1, 3), (4, 2))
#: contacts owned by each ring, in the order of the ring's superelement DOFs
RING_CONTACTS = {"outer": (1, 4), "inner": (2, 3)}
#: for each diagonal, the index (0 or 1) of its contact within the ring's own pair
OUTER_SLOT = np.array([RING_CONTACTS["outer"].index(c) for c, _ in DIAGONALS])  # 0, 1
INNER_SLOT = np.array([RING_CONTACTS["inner"].index(c) for _, c in DIAGONALS])  # 1, 0


class BearingDefinitionError(ValueError):
    """A bearing definition value breaks a rule. The message names the key,
    the value and the rule."""


def fail(key: str, value: Any, rule: str):
    raise BearingDefinitionError(f"{key} = {value!r}: {rule}")


#: the tables of a bearing definition file and the keys each one knows (names are case-sensitive)
BEARING_TABLES = {
    "bearing": ("name", "pitch_diameter_mm", "ball_diameter_mm", "groove_radius_mm", "contact_angle_deg",
                "ball_count", "preload_um", "first_ball_angle_deg", "moving_ring"),
    "material": ("youngs_modulus_gpa", "poisson_ratio"),
    "rings": ("gap_mm", "outer_ring_outer_diameter_mm", "inner_ring_bore_diameter_mm", "outer_ring_height_mm",
              "inner_ring_height_mm", "outer_ring_bolted_face", "inner_ring_bolted_face"),
    "errors": ("outer_ring_csv", "inner_ring_csv", "ball_diameters_csv", "synthetic"),
    # sub-tables [connection.outer], [connection.inner]; their keys: bearing/connection.py
    "connection": ("outer", "inner"),
}


def check_known_keys(table: Mapping[str, Any], name: str, known) -> None:
    """Refuse a key of the table ``[name]`` that is not in ``known``, naming the table, the key, its
    value and the known keys (a misspelt key would otherwise be ignored and its default used)."""
    for key in table:
        if key not in known:
            fail(f"{name}.{key}", table[key],
                  f"unknown key in table [{name}] (known: {', '.join(sorted(known))}; names are case-sensitive)")
