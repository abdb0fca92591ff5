"""A scene's solids: the one description of its geometry that both the ray caster's
triangles (:func:`homing_gym.render.worldmesh.world_mesh`) and PyBullet's bodies
(:class:`homing_gym.sim.simulator.Simulator`) are built from, so that what the robot sees is
what it bumps into.

A wall is a box whose length takes in the wall's thickness (so that walls meeting at a
corner close it), a box or panel landmark a box, a cylinder landmark a cylinder (drawn as a
64-sided prism, collided with as the true cylinder: the two differ by at most 0.1 % of the
radius). The floor is a rectangle :data:`FLOOR_MARGIN` beyond the scene bounds (PyBullet
collides with an infinite plane through its top face); the fence, four invisible walls
just outside the bounds, is collided with and never drawn. Mesh parts
(:class:`~homing_gym.scenes.mesh_part.MeshPart`) are their own triangles and are not
repeated here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from homing_gym.scenes.base import Color, Landmark, Scene, Wall

#: Margin (metres) of the floor beyond the scene bounds.
FLOOR_MARGIN = 2.0
#: How far (metres) the floor lies below z = 0 in scenes with mesh parts, so that a mesh's
#: own ground at z = 0 is drawn instead of flickering against it.
MESH_FLOOR_DROP = 0.002
#: Thickness (metres) of the fence's walls; they are 1 m high.
FENCE_THICKNESS = 0.1
#: The shapes a :class:`Solid` can take.
SHAPES = ("box", "panel", "cylinder")


@dataclass(frozen=True)
class Solid:
    """A box, panel or upright cylinder standing in a scene.

    ``centre`` (metres) is the centre of its volume; ``half`` its half extents along its
    own x, y (after turning by ``yaw`` radians counter-clockwise about z) and z; a
    cylinder's are ``(radius, radius, height / 2)``. A ``panel`` is a box whose local +y
    side carries its whole texture once (u left to right seen from the front, v bottom to
    top) and whose other sides take the texture's top-left texel; a box shows its texture
    once on every side, a cylinder once around its side. ``color`` is RGBA in ``[0, 1]``,
    multiplied with the texture as PyBullet does."""

    shape: str
    centre: tuple[float, float, float]
    half: tuple[float, float, float]
    yaw: float = 0.0
    color: Color = (1.0, 1.0, 1.0, 1.0)
    texture: str | None = None

    def __post_init__(self) -> None:
        if self.shape not in SHAPES:
            raise ValueError(f"unknown solid shape {self.shape!r}; allowed: {list(SHAPES)}")

    @property
    def radius(self) -> float:
        """A cylinder's radius (metres)."""
        return self.half[0]

    @property
    def height(self) -> float:
        """Height (metres)."""
        return 2 * self.half[2]


def wall_solid(wall: Wall) -> Solid:
    """The box of a wall."""
    (x0, y0), (x1, y1) = wall.start, wall.end
    return Solid("box", ((x0 + x1) / 2, (y0 + y1) / 2, wall.height / 2),
                 ((wall.length + wall.thickness) / 2, wall.thickness / 2, wall.height / 2),
                 math.atan2(y1 - y0, x1 - x0), wall.color, wall.texture)


def landmark_solid(landmark: Landmark) -> Solid:
    """The box, panel or cylinder of a landmark standing on its ``base``."""
    lm = landmark
    centre = (lm.position[0], lm.position[1], lm.base + lm.height / 2)
    half = ((lm.radius, lm.radius) if lm.shape == "cylinder"
            else (lm.extent[0] / 2, lm.extent[1] / 2))
    return Solid(lm.shape, centre, (*half, lm.height / 2), lm.yaw, lm.color, lm.texture)


def floor_top(scene: Scene) -> float:
    """Height (metres) of the floor's top face: 0, or :data:`MESH_FLOOR_DROP` below 0 in a
    scene with mesh parts."""
    return -MESH_FLOOR_DROP if scene.meshes else 0.0


def floor_rectangle(scene: Scene) -> tuple[float, float, float, float]:
    """``(xmin, ymin, xmax, ymax)`` (metres) of the floor's top face."""
    (xmin, ymin), (xmax, ymax) = scene.bounds
    return xmin - FLOOR_MARGIN, ymin - FLOOR_MARGIN, xmax + FLOOR_MARGIN, ymax + FLOOR_MARGIN


def fence_solids(scene: Scene) -> list[Solid]:
    """The fence's four walls, just outside ``scene.bounds``, 1 m high."""
    (xmin, ymin), (xmax, ymax) = scene.bounds
    t = FENCE_THICKNESS
    cx, cy, hx, hy = (xmin + xmax) / 2, (ymin + ymax) / 2, (xmax - xmin) / 2, (ymax - ymin) / 2
    boxes = (((cx, ymin - t / 2), (hx + t, t / 2)), ((cx, ymax + t / 2), (hx + t, t / 2)),
             ((xmin - t / 2, cy), (t / 2, hy + t)), ((xmax + t / 2, cy), (t / 2, hy + t)))
    return [Solid("box", (*centre, 0.5), (*half, 0.5)) for centre, half in boxes]
