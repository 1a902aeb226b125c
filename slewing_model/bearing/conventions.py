"""The conventions of the whole package (``DESIGN.md``): contact numbering, and the tables of a
bearing definition file with the error its readers raise.

* Contact 1 = upper-outer, 3 = lower-inner (diagonal 1, loaded when the inner ring is pushed
  towards +z); 4 = lower-outer, 2 = upper-inner (diagonal 2). The outer ring owns contacts 1
  and 4, the inner ring 2 and 3.
"""
from __future__ import annotations

import json
import math
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


def toml_value(value: Any, limit: int = 80) -> str:
    """``value`` spelt as in a TOML file (``true``, ``"text"``, ``[1, 2]``, ``inf``, ``{ a = 1 }``), for
    messages about definition files; a long array or inline table is cut after ``limit`` characters."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return ("nan" if math.isnan(v) else "inf" if v > 0 else "-inf") if not math.isfinite(v) else repr(v)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple, np.ndarray)):
        text = "[" + ", ".join(toml_value(v, limit) for v in value) + "]"
    elif isinstance(value, Mapping):
        text = "{ " + ", ".join(f"{_toml_key(k)} = {toml_value(v, limit)}" for k, v in value.items()) + " }"
    elif hasattr(value, "isoformat"):
        return value.isoformat()
    else:
        return repr(value)          # not from a TOML file (a Python caller's object)
    return text if len(text) <= limit else text[:limit - 5] + " ... " + text[-1]


def _toml_key(key: Any) -> str:
    key = str(key)
    return key if key and all(c.isalnum() and c.isascii() or c in "_-" for c in key) else json.dumps(key)


def definition_message(key: str, value: Any, rule: str) -> str:
    """The message of a refused definition value, in the spelling of the TOML file: ``key = value: rule``
    (``value`` as :func:`toml_value` writes it). ``value`` None means the key is absent (TOML has no
    null): a rule starting "missing key" then names the key's table and its last part,
    ``[connection.outer]: missing key `length_mm` (required)``; another rule is the message alone when
    it names the key, else follows ``key: ``."""
    if value is not None:
        return f"{key} = {toml_value(value)}: {rule}"
    table, _, short = key.rpartition(".")
    if rule.startswith("missing key"):
        rule = f"missing key `{short}`{rule[len('missing key'):]}"
        return f"[{table}]: {rule}" if table else rule
    return rule if key in rule else f"{key}: {rule}"


def fail(key: str, value: Any, rule: str):
    raise BearingDefinitionError(definition_message(key, value, rule))


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
        if key not in known and isinstance(table[key], Mapping):   # a misspelt [name.key] sub-table
            fail(f"{name}.{key}", None, f"unknown table [{name}.{key}] "
                 f"(known: {', '.join(sorted(known))}; names are case-sensitive)")
        if key not in known:
            fail(f"{name}.{key}", table[key],
                  f"unknown key in table [{name}] (known: {', '.join(sorted(known))}; names are case-sensitive)")
