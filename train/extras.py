"""Optional dependencies: one line saying which extra to install when one is missing."""

from __future__ import annotations

import importlib.util

#: The modules each extra of ``pyproject.toml`` provides, as far as the code imports them.
EXTRAS = {"train": ("stable_baselines3", "torch"), "video": ("moviepy",), "ray": ("ray",)}


class MissingExtraError(ImportError):
    """An optional dependency is not installed; the message names the extra."""


def missing_extra(extra: str) -> str | None:
    """``None`` when the modules of ``extra`` can be imported, else the install hint."""
    missing = [m for m in EXTRAS[extra] if importlib.util.find_spec(m) is None]
    if not missing:
        return None
    return (f"{', '.join(missing)} not installed: pip install \"homing-gym[{extra}]\"")


def require_extra(extra: str, what: str) -> None:
    """``MissingExtraError`` naming ``what`` needs and the extra to install."""
    hint = missing_extra(extra)
    if hint:
        raise MissingExtraError(f"{what} needs the [{extra}] extra: {hint}")
