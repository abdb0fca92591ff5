"""Checks of user-given numbers, each failing with one ``ValueError`` that names the value."""

from __future__ import annotations

import math
import numbers


def is_real(value) -> bool:
    """Whether ``value`` is a finite real number (a Python or numpy int or float; not a
    bool, a string or ``None``)."""
    return (isinstance(value, numbers.Real) and not isinstance(value, bool)
            and math.isfinite(value))


def require_positive(name: str, value, unit: str = "") -> float:
    """``value`` as a float if it is a real, finite number above zero (not a bool or a
    string); else ``ValueError`` naming ``name``, the value and the unit (e.g. "metres")."""
    if not (is_real(value) and value > 0):
        of = f" of {unit}" if unit else ""
        raise ValueError(f"{name} must be a positive number{of}, got {value!r}")
    return float(value)


def require_number(name: str, value, low: float, high: float, unit: str = "", *,
                   integer: bool = False, high_open: bool = False,
                   low_open: bool = False) -> float:
    """``value`` if it is a finite real number (an integer when ``integer``) in
    ``[low, high]`` (without ``high`` when ``high_open``, without ``low`` when
    ``low_open``); else ``ValueError`` naming ``name``, the range, the unit and the value.
    Returns a float, or an int when ``integer``."""
    ok = is_real(value) and (not integer or isinstance(value, numbers.Integral)) and (
        (low < value if low_open else low <= value)
        and (value < high if high_open else value <= high))
    if not ok:
        kind = "an integer" if integer else "a number"
        of = f" {unit}" if unit else ""
        raise ValueError(f"{name} must be {kind} in "
                         f"{interval(low, high, integer, low_open, high_open)}{of}, "
                         f"got {value!r}")
    return int(value) if integer else float(value)


def interval(low: float, high: float, integer: bool = False, low_open: bool = False,
             high_open: bool = False) -> str:
    """``[low, high]`` as text, a parenthesis at an open end; integers with thousands
    separators."""
    shown = (lambda v: f"{int(v):,}") if integer else (lambda v: f"{v:g}")
    return (f"{'(' if low_open else '['}{shown(low)}, {shown(high)}"
            f"{')' if high_open else ']'}")


def require_sequence(name: str, value, length: int, what: str) -> tuple:
    """``value`` as a tuple if it is a sequence (not a string) of ``length`` items; else
    ``ValueError`` naming ``name``, ``what`` it should hold (e.g. "(H, W) integers")
    and the value."""
    try:
        items = None if isinstance(value, (str, bytes, dict)) else tuple(value)
    except TypeError:               # not iterable
        items = None
    if items is None or len(items) != length:
        raise ValueError(f"{name} must be {what}, got {value!r}")
    return items
