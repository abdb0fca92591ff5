"""How a world looks beyond its geometry: its sky's gradient, its light, its shadows and
the height of the robot's camera, as plain data a :class:`~homing_gym.scenes.base.Scene`
carries (``Scene.appearance``), and :func:`random_appearance`, which the world families
(:mod:`homing_gym.scenes.families`) draw per world.

Every field defaults to "nothing special": ``None`` defers to the env's argument of the
same name (``shadows``, ``camera_height``) and then to the env's default. An env
argument given explicitly always wins over the world's (a user who asks for
``camera_height=0.1`` gets it in every world).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from homing_gym.validation import is_real, require_number, require_sequence

RGB = tuple[float, float, float]
#: Camera heights (metres above the floor) a family draws from unless told otherwise:
#: from an ant's eye (a few centimetres, grass blades tower over it) to a tall robot's.
CAMERA_HEIGHTS = (0.02, 0.5)
#: Bounds of an appearance's camera height (metres): :class:`~homing_gym.config.EnvConfig`'s.
CAMERA_HEIGHT_RANGE = (0.005, 5.0)


def _rgb(owner: str, value) -> RGB:
    rgb = require_sequence(owner, value, 3, "three RGB values in [0, 1]")
    for c in rgb:
        require_number(owner, c, 0.0, 1.0, "")
    return tuple(float(c) for c in rgb)


@dataclass(frozen=True)
class Appearance:
    """A world's looks beyond its geometry.

    ``sky_zenith``: RGB in [0, 1] of the sky straight up; the ray caster blends it
    linearly in elevation from the scene's ``sky_color`` at the horizon (``None``: a
    uniform sky). ``light_direction`` (towards the light, world frame; its length does
    not matter), ``ambient`` and ``diffuse`` (the Lambert terms of the ray caster and
    TinyRenderer; ``None`` direction: the renderers' default light). ``shadows``: objects
    cast shadows from that light (``None``: the env's ``shadows``). ``camera_height``:
    metres above the floor (``None``: the env's ``camera_height``). Checked on
    construction (``ValueError`` naming the field)."""

    sky_zenith: RGB | None = None
    light_direction: tuple[float, float, float] | None = None
    ambient: float = 0.6
    diffuse: float = 0.45
    shadows: bool | None = None
    camera_height: float | None = None

    def __post_init__(self) -> None:
        if self.sky_zenith is not None:
            object.__setattr__(self, "sky_zenith", _rgb("appearance sky_zenith",
                                                        self.sky_zenith))
        if self.light_direction is not None:
            d = require_sequence("appearance light_direction", self.light_direction, 3,
                                 "three finite numbers, not all zero")
            if not all(is_real(v) for v in d) or not any(d):
                raise ValueError(f"appearance light_direction must be three finite numbers, "
                                 f"not all zero, got {self.light_direction!r}")
            object.__setattr__(self, "light_direction", tuple(float(v) for v in d))
        require_number("appearance ambient", self.ambient, 0.0, 2.0, "")
        require_number("appearance diffuse", self.diffuse, 0.0, 2.0, "")
        if self.shadows not in (None, True, False):
            raise ValueError(f"appearance shadows must be None, True or False, got "
                             f"{self.shadows!r}")
        if self.camera_height is not None:
            require_number("appearance camera_height", self.camera_height,
                           *CAMERA_HEIGHT_RANGE, "metres")


#: A world with no appearance of its own.
PLAIN = Appearance()


def random_appearance(rng: np.random.Generator, *, outdoor: bool,
                      camera_heights: tuple[float, float] = CAMERA_HEIGHTS) -> tuple[RGB, Appearance]:
    """A world's sky colour at the horizon and its :class:`Appearance`, drawn from
    ``rng``: outdoors a blue to grey-white sky (sometimes dusk-tinted) growing deeper
    towards the zenith, the sun 15-75 degrees up at any azimuth; indoors a light grey sky
    (seen only through gaps) and the light 50-90 degrees up (ceiling lamps); ambient
    0.35-0.75 and diffuse 0.25-0.65 (dim to bright, flat to contrasty); shadows in half
    the worlds; the camera height uniform in ``camera_heights`` metres."""
    if outdoor:
        horizon = np.array([rng.uniform(0.6, 0.95), rng.uniform(0.7, 0.95), rng.uniform(0.8, 1.0)])
        if rng.random() < 0.2:                               # dusk: a warm horizon
            horizon = np.array([rng.uniform(0.85, 1.0), rng.uniform(0.6, 0.8),
                                rng.uniform(0.45, 0.65)])
        zenith = horizon * rng.uniform(0.45, 0.9, 3) * [0.7, 0.85, 1.0]
        elevation = rng.uniform(math.radians(15), math.radians(75))
    else:
        horizon = np.full(3, rng.uniform(0.75, 0.95))
        zenith = horizon * rng.uniform(0.85, 1.0)
        elevation = rng.uniform(math.radians(50), math.radians(90))
    azimuth = rng.uniform(-math.pi, math.pi)
    direction = (math.cos(elevation) * math.cos(azimuth),
                 math.cos(elevation) * math.sin(azimuth), math.sin(elevation))
    low, high = camera_heights
    appearance = Appearance(
        sky_zenith=tuple(float(c) for c in np.clip(zenith, 0, 1)),
        light_direction=direction, ambient=float(rng.uniform(0.35, 0.75)),
        diffuse=float(rng.uniform(0.25, 0.65)), shadows=bool(rng.random() < 0.5),
        camera_height=float(rng.uniform(low, high)))
    return tuple(float(c) for c in np.clip(horizon, 0, 1)), appearance
