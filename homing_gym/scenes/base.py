"""Declarative scene description: floor, walls and landmarks as frozen dataclasses.

A scene is plain data; :class:`~homing_gym.simulator.Simulator` turns it into PyBullet
bodies. Units: metres and radians (yaw counter-clockwise from world +x). Colours are
RGBA in ``[0, 1]``. A texture is the name of a PNG shipped in ``homing_gym/assets/textures``
(see :func:`homing_gym.textures.available_textures`) or a path to a PNG file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from homing_gym.textures import check_texture

SHAPES = ("cylinder", "box", "panel")

Color = tuple[float, float, float, float]


def _check_positive(owner: str, name: str, value: float) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise ValueError(f"{owner}: {name} must be a positive number of metres, got {value!r}")


def _check_color(owner: str, color: Color) -> None:
    if len(color) != 4 or not all(0.0 <= c <= 1.0 for c in color):
        raise ValueError(f"{owner}: color must be 4 RGBA values in [0, 1], got {color!r}")


@dataclass(frozen=True)
class Landmark:
    """A static object: on the floor, or hanging with its bottom ``base`` metres above it
    (posters, lamps).

    ``shape`` is ``"cylinder"`` (uses ``radius``), ``"box"`` (uses ``extent`` =
    (length along its yaw, width), metres) or ``"panel"``: a box like ``"box"`` whose
    front face, the one on the left of the yaw direction (local +y), shows ``texture``
    exactly once, upright and unmirrored (a wall-mounted sign; its other faces take the
    texture's top-left pixel). ``position`` is the centre of its footprint.
    """

    position: tuple[float, float]
    shape: str = "cylinder"
    radius: float = 0.1075
    extent: tuple[float, float] = (0.2, 0.2)
    height: float = 0.385
    yaw: float = 0.0
    color: Color = (0.85, 0.1, 0.1, 1.0)
    texture: str | None = None
    name: str = ""
    base: float = 0.0

    def __post_init__(self) -> None:
        owner = f"landmark {self.name or self.position!r}"
        if not (math.isfinite(self.base) and self.base >= 0):
            raise ValueError(f"{owner}: base must be >= 0 metres above the floor, "
                             f"got {self.base!r}")
        if self.shape not in SHAPES:
            raise ValueError(f"{owner}: unknown shape {self.shape!r}; allowed: {SHAPES}")
        if self.shape == "cylinder":
            _check_positive(owner, "radius", self.radius)
        else:
            for value in self.extent:
                _check_positive(owner, "extent", value)
        _check_positive(owner, "height", self.height)
        _check_color(owner, self.color)
        if self.texture is not None:
            check_texture(self.texture)

    @property
    def footprint_radius(self) -> float:
        """Radius (metres) of the smallest circle around the footprint."""
        if self.shape == "cylinder":
            return self.radius
        return math.hypot(*self.extent) / 2

    @property
    def footprint_half_size(self) -> tuple[float, float]:
        """Half width and half depth (metres) of the footprint's axis-aligned bounding box."""
        if self.shape == "cylinder":
            return self.radius, self.radius
        c, s = abs(math.cos(self.yaw)), abs(math.sin(self.yaw))
        a, b = self.extent[0] / 2, self.extent[1] / 2
        return a * c + b * s, a * s + b * c


@dataclass(frozen=True)
class Wall:
    """A straight wall from ``start`` to ``end`` (metres), standing on the floor."""

    start: tuple[float, float]
    end: tuple[float, float]
    height: float = 0.5
    thickness: float = 0.05
    color: Color = (0.92, 0.92, 0.9, 1.0)
    texture: str | None = None

    def __post_init__(self) -> None:
        owner = f"wall {self.start!r}->{self.end!r}"
        _check_positive(owner, "length", self.length)
        _check_positive(owner, "height", self.height)
        _check_positive(owner, "thickness", self.thickness)
        _check_color(owner, self.color)
        if self.texture is not None:
            check_texture(self.texture)

    @property
    def length(self) -> float:
        return math.dist(self.start, self.end)


@dataclass(frozen=True)
class Scene:
    """A world: the free floor area ``bounds`` = ((xmin, ymin), (xmax, ymax)), walls and
    landmarks. Every landmark must lie inside ``bounds``; the robot is placed inside them."""

    name: str
    bounds: tuple[tuple[float, float], tuple[float, float]]
    walls: tuple[Wall, ...] = ()
    landmarks: tuple[Landmark, ...] = ()
    floor_color: Color = (0.55, 0.55, 0.55, 1.0)
    floor_texture: str | None = None
    metadata: dict = field(default_factory=dict, compare=False, hash=False)

    def __post_init__(self) -> None:
        (xmin, ymin), (xmax, ymax) = self.bounds
        if not (xmax > xmin and ymax > ymin):
            raise ValueError(f"scene {self.name!r}: empty bounds {self.bounds!r}")
        for lm in self.landmarks:
            x, y = lm.position
            hx, hy = lm.footprint_half_size
            if not (xmin <= x - hx and x + hx <= xmax and ymin <= y - hy and y + hy <= ymax):
                raise ValueError(
                    f"scene {self.name!r}: landmark {lm.name or ''} at {lm.position!r} "
                    f"(footprint half size {hx:.3f} x {hy:.3f} m) lies outside the scene "
                    f"bounds x in [{xmin}, {xmax}], y in [{ymin}, {ymax}]")
        _check_color(f"scene {self.name!r} floor", self.floor_color)
        if self.floor_texture is not None:
            check_texture(self.floor_texture)

    @property
    def size(self) -> tuple[float, float]:
        """Width and depth of the free area (metres)."""
        (xmin, ymin), (xmax, ymax) = self.bounds
        return xmax - xmin, ymax - ymin


def square_walls(side: float, **wall_kwargs) -> tuple[Wall, ...]:
    """Four walls whose inner faces enclose a ``side`` x ``side`` square centred at the origin."""
    _check_positive("square_walls", "side", side)
    t = wall_kwargs.get("thickness", Wall.thickness)
    h = side / 2 + t / 2
    corners = [(-h, -h), (h, -h), (h, h), (-h, h)]
    return tuple(Wall(corners[i], corners[(i + 1) % 4], **wall_kwargs) for i in range(4))


def _segment_distance(point: tuple[float, float], a, b) -> float:
    ax, ay = a
    bx, by = b
    px, py = point
    dx, dy = bx - ax, by - ay
    t = max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy)))
    return math.hypot(px - ax - t * dx, py - ay - t * dy)


def landmark_distance(lm: Landmark, point: tuple[float, float]) -> float:
    """Distance (metres) from a floor point to the landmark's footprint (0 inside)."""
    dx, dy = point[0] - lm.position[0], point[1] - lm.position[1]
    if lm.shape == "cylinder":
        return max(0.0, math.hypot(dx, dy) - lm.radius)
    c, s = math.cos(lm.yaw), math.sin(lm.yaw)
    lx, ly = abs(c * dx + s * dy) - lm.extent[0] / 2, abs(-s * dx + c * dy) - lm.extent[1] / 2
    return math.hypot(max(lx, 0.0), max(ly, 0.0))


def clearance(scene: Scene, point: tuple[float, float]) -> float:
    """Free distance (metres) from a floor point to the nearest wall, landmark or scene
    boundary; 0 or less means the point is blocked or outside ``scene.bounds``."""
    (xmin, ymin), (xmax, ymax) = scene.bounds
    x, y = point
    free = min(x - xmin, xmax - x, y - ymin, ymax - y)
    for wall in scene.walls:
        free = min(free, _segment_distance(point, wall.start, wall.end) - wall.thickness / 2)
    for lm in scene.landmarks:
        free = min(free, landmark_distance(lm, point))
    return free
