"""Checks of user-given numbers, each failing with one ``ValueError`` that names the value."""

from __future__ import annotations

import math
import numbers


def require_positive(name: str, value, unit: str = "") -> float:
    """``value`` as a float if it is a real, finite number above zero (not a bool or a
    string); else ``ValueError`` naming ``name``, the value and the unit (e.g. "metres")."""
    ok = (isinstance(value, numbers.Real) and not isinstance(value, bool)
          and math.isfinite(value) and value > 0)
    if not ok:
        of = f" of {unit}" if unit else ""
        raise ValueError(f"{name} must be a positive number{of}, got {value!r}")
    return float(value)
