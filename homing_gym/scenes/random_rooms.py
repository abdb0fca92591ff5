"""``random_rooms``: a procedural indoor world, new every episode (drawn from the
episode's random generator, so ``reset(seed=...)`` reproduces it).

A rectangular floor of 5-9 x 4-7 m is cut by straight interior walls into a grid of
1-3 x 1-2 rooms, each at least :data:`MIN_ROOM` metres wide. Every stretch of interior
wall between two neighbouring rooms has a door (0.9-1.3 m), or with probability
:data:`OPEN_PROBABILITY` is left out (an open plan), so every room can be reached. Walls
(1-2.6 m high) and floor are textured or plain (as in ``random_arena``). Each room gets
furniture (boxes against its walls or standing free: 0.3-1.2 m long, 0.25-1.0 m high),
plants (green cylinders), and pictures (textured panels, tinted, hung 0.15-0.6 m above
the floor on either face of a wall). Furniture never blocks a door: a piece is kept only
if the floor stays one connected free area for the robot (0.2 m disc) on an 8 cm grid.
``scene.metadata["rooms"]`` lists the rooms as ((xmin, ymin), (xmax, ymax)) rectangles.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage

from homing_gym.scenes.base import Landmark, Scene, Wall, clearances
from homing_gym.scenes.random_arena import FLOOR_TEXTURES, WALL_TEXTURES, _surface

MIN_ROOM = 2.0
WALL_T = 0.1
OPEN_PROBABILITY = 0.2
DOOR_WIDTH = (0.9, 1.3)
PICTURE_TEXTURES = ("poster_a", "poster_b", "stripes_warm", "stripes_cool", "checker_green",
                    "checker_dark", "bricks_red", "wood_light")
#: The disc (metres) that must be able to reach every part of the floor, and the grid.
ROBOT_DISC, CHECK_GRID = 0.2, 0.08


def _cuts(length: float, rooms: int, rng: np.random.Generator) -> list[float]:
    """Positions of the walls that divide ``[-length/2, length/2]`` into ``rooms``
    rooms of at least :data:`MIN_ROOM` metres, jittered around an even split."""
    even = np.linspace(-length / 2, length / 2, rooms + 1)
    slack = (length / rooms - MIN_ROOM) / 2
    return [float(c + rng.uniform(-slack, slack)) for c in even[1:-1]]


def _wall_with_door(a: tuple[float, float], b: tuple[float, float], rng, style: dict,
                    doors: list) -> list[Wall]:
    """The interior wall from ``a`` to ``b``: two pieces around a door (its centre is
    added to ``doors``), or nothing (an open plan)."""
    if rng.random() < OPEN_PROBABILITY:
        return []
    length = math.dist(a, b)
    width = float(rng.uniform(*DOOR_WIDTH))
    centre = float(rng.uniform(width / 2 + 0.3, length - width / 2 - 0.3))
    ux, uy = (b[0] - a[0]) / length, (b[1] - a[1]) / length
    at = lambda s: (a[0] + s * ux, a[1] + s * uy)  # noqa: E731
    doors.append(at(centre))
    return [Wall(a, at(centre - width / 2), **style), Wall(at(centre + width / 2), b, **style)]


class _FreeFloor:
    """The clearance of every :data:`CHECK_GRID` point of ``scene``'s floor, kept up to
    date as landmarks are added: a new landmark's clearance alone (with the bounds) is
    folded in by a minimum, which gives the same values as :func:`clearances` of the
    whole scene (a minimum over the parts) at the cost of one landmark."""

    def __init__(self, scene: Scene):
        (xmin, ymin), (xmax, ymax) = scene.bounds
        gx, gy = np.meshgrid(np.arange(xmin, xmax, CHECK_GRID),
                             np.arange(ymin, ymax, CHECK_GRID), indexing="ij")
        self.shape, self.bounds = gx.shape, scene.bounds
        self.points = np.stack([gx.ravel(), gy.ravel()], 1)
        self.free = clearances(scene, self.points)

    def with_landmark(self, landmark: Landmark) -> np.ndarray:
        """The grid's clearances (metres) once ``landmark`` stands on the floor too."""
        alone = Scene(name="landmark", bounds=self.bounds, walls=(), landmarks=(landmark,))
        return np.minimum(self.free, clearances(alone, self.points))

    def connected(self, free: np.ndarray) -> bool:
        """Whether the points of the clearances ``free`` where the robot's disc fits make
        one connected area."""
        return ndimage.label((free >= ROBOT_DISC).reshape(self.shape))[1] == 1


def _picture(wall: Wall, rng: np.random.Generator, side: float) -> Landmark | None:
    """A tinted textured panel on the ``side`` (+1: left of start->end) face of ``wall``."""
    length = wall.length
    width = float(rng.uniform(0.3, 0.8))
    if length < width + 0.2:
        return None
    s = float(rng.uniform(width / 2 + 0.1, length - width / 2 - 0.1))
    (x0, y0), (x1, y1) = wall.start, wall.end
    ux, uy = (x1 - x0) / length, (y1 - y0) / length
    nx, ny = -uy * side, ux * side
    off = wall.thickness / 2 + 0.011
    height = float(rng.uniform(0.25, 0.6))
    tint = tuple(float(c) for c in rng.uniform(0.5, 1.0, 3)) + (1.0,)
    return Landmark(position=(x0 + s * ux + off * nx, y0 + s * uy + off * ny), shape="panel",
                    extent=(width, 0.02), height=height,
                    base=float(rng.uniform(0.15, min(0.6, wall.height - height))),
                    yaw=math.atan2(ny, nx) - math.pi / 2, color=tint,
                    texture=str(rng.choice(PICTURE_TEXTURES)), name="picture")


def _furniture(room, rng: np.random.Generator) -> Landmark:
    """A box against one of ``room``'s walls (or, one time in three, standing free)."""
    (xmin, ymin), (xmax, ymax) = room
    length, depth = float(rng.uniform(0.3, 1.2)), float(rng.uniform(0.3, 0.7))
    yaw = float(rng.choice([0.0, math.pi / 2]))
    hx, hy = (length / 2, depth / 2) if yaw == 0.0 else (depth / 2, length / 2)
    x = float(rng.uniform(xmin + hx + 0.06, xmax - hx - 0.06))
    y = float(rng.uniform(ymin + hy + 0.06, ymax - hy - 0.06))
    if rng.random() < 2 / 3:                      # pushed against a wall
        side = int(rng.integers(4))
        x = (xmin + hx + 0.06, xmax - hx - 0.06, x, x)[side]
        y = (y, y, ymin + hy + 0.06, ymax - hy - 0.06)[side]
    surface = _surface(rng, ("wood_light", "wood_dark", "stripes_warm", "checker_dark"),
                       low=0.2, high=0.9)
    color = (surface["color"] if surface["texture"] is None
             else tuple(float(c) for c in rng.uniform(0.6, 1.0, 3)) + (1.0,))
    return Landmark(position=(x, y), shape="box", extent=(length, depth),
                    height=float(rng.uniform(0.25, 1.0)), yaw=yaw, color=color,
                    texture=surface["texture"], name="furniture")


def _plant(room, rng: np.random.Generator) -> Landmark:
    (xmin, ymin), (xmax, ymax) = room
    r = float(rng.uniform(0.1, 0.25))
    return Landmark(position=(float(rng.uniform(xmin + r + 0.06, xmax - r - 0.06)),
                              float(rng.uniform(ymin + r + 0.06, ymax - r - 0.06))),
                    radius=r, height=float(rng.uniform(0.4, 1.2)),
                    color=(float(rng.uniform(0.05, 0.3)), float(rng.uniform(0.35, 0.7)),
                           float(rng.uniform(0.05, 0.3)), 1.0), name="plant")


def random_rooms_scene(rng: np.random.Generator) -> Scene:
    """Draw a ``random_rooms`` world from ``rng`` (see the module doc)."""
    width, depth = float(rng.uniform(5.0, 9.0)), float(rng.uniform(4.0, 7.0))
    nx = int(rng.integers(1, min(3, int(width // MIN_ROOM)) + 1))
    ny = int(rng.integers(1, min(2, int(depth // MIN_ROOM)) + 1))
    xs = [-width / 2, *_cuts(width, nx, rng), width / 2]
    ys = [-depth / 2, *_cuts(depth, ny, rng), depth / 2]
    height = float(rng.uniform(1.0, 2.6))
    walls: list[Wall] = []
    h, t = width / 2 + WALL_T / 2, depth / 2 + WALL_T / 2
    for a, b in (((-h, -t), (h, -t)), ((h, -t), (h, t)), ((h, t), (-h, t)), ((-h, t), (-h, -t))):
        walls.append(Wall(a, b, height=height, thickness=WALL_T,
                          **_surface(rng, WALL_TEXTURES, low=0.7, high=1.0)))
    doors: list = []
    for i in range(nx):
        for j in range(ny):
            style = dict(height=height, thickness=WALL_T,
                         **_surface(rng, WALL_TEXTURES, low=0.7, high=1.0))
            if i + 1 < nx:   # the wall to the east neighbour
                walls += _wall_with_door((xs[i + 1], ys[j]), (xs[i + 1], ys[j + 1]), rng,
                                         style, doors)
            if j + 1 < ny:   # the wall to the north neighbour
                walls += _wall_with_door((xs[i], ys[j + 1]), (xs[i + 1], ys[j + 1]), rng,
                                         style, doors)
    rooms = [((xs[i] + WALL_T / 2 * (i > 0), ys[j] + WALL_T / 2 * (j > 0)),
              (xs[i + 1] - WALL_T / 2 * (i + 1 < nx), ys[j + 1] - WALL_T / 2 * (j + 1 < ny)))
             for i in range(nx) for j in range(ny)]
    floor = _surface(rng, FLOOR_TEXTURES, low=0.3, high=0.8)
    # the outer walls run counter-clockwise: their left face (+1) looks into the house
    sides = [1.0] * 4 + [float(rng.choice([-1.0, 1.0])) for _ in walls[4:]]
    landmarks = [p for wall, side in zip(walls, sides) for _ in range(int(rng.integers(0, 2)))
                 if (p := _picture(wall, rng, side)) is not None]

    def scene_with(items) -> Scene:
        return Scene(name="random_rooms", bounds=((-width / 2, -depth / 2), (width / 2, depth / 2)),
                     walls=tuple(walls), landmarks=tuple(items), floor_color=floor["color"],
                     floor_texture=floor["texture"], metadata={"rooms": rooms})

    items = list(landmarks)
    floor_grid = _FreeFloor(scene_with(items))
    for room in rooms:
        for _ in range(int(rng.integers(1, 5))):
            item = _furniture(room, rng) if rng.random() < 0.75 else _plant(room, rng)
            if doors and min(math.dist(item.position, d) for d in doors) < 0.8:
                continue                          # keep doorways clear
            free = floor_grid.with_landmark(item)
            if floor_grid.connected(free):
                items.append(item)
                floor_grid.free = free
    return scene_with(items)
