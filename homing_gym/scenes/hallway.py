"""``hallway``: an indoor corridor like the one of Hong et al. 1991 §5.

A corridor 8 m long (x from 0 to 8) and 1.8 m wide (y from -0.9 to 0.9) with 2.4 m
concrete walls and end walls, a dark skirting board, wooden doors on both sides,
posters, wall lamps, and a few objects standing along the walls (a bin, a bench, a fire
extinguisher, a plant pot). The camera is 0.30 m above the floor with a +-30 degree
vertical field of view, so everything that should appear in the horizon band is
mounted low: posters from 0.35 m, lamps at 0.55-0.75 m (real ones hang higher; ours would
otherwise be invisible).

``scene.metadata["route_origin"]`` is the pose ``(x, y, yaw)`` of the first target of the
route of ``RouteFollowing-v0``: on the centre line, facing along the corridor (+x).
"""

from __future__ import annotations

from homing_gym.scenes.base import Landmark, Scene, Wall

LENGTH, HALF_WIDTH, HEIGHT = 8.0, 0.9, 2.4
WALL_T = 0.05
WOOD = (0.62, 0.45, 0.3, 1.0)
WHITE = (1.0, 1.0, 1.0, 1.0)
LAMP = (1.0, 0.97, 0.8, 1.0)
ROUTE_ORIGIN = (1.2, 0.0, 0.0)


def _on_wall(x: float, side: int, width: float, height: float, base: float, depth: float,
             **kwargs) -> Landmark:
    """A flat box against the left (``side=+1``) or right (``side=-1``) wall."""
    y = side * (HALF_WIDTH - depth / 2)
    return Landmark(position=(x, y), shape="box", extent=(width, depth), height=height,
                    base=base, **kwargs)


def hallway_scene() -> Scene:
    """The fixed ``hallway`` scene."""
    walls = (
        Wall((0.0, HALF_WIDTH + WALL_T / 2), (LENGTH, HALF_WIDTH + WALL_T / 2), HEIGHT, WALL_T,
             texture="concrete"),
        Wall((0.0, -HALF_WIDTH - WALL_T / 2), (LENGTH, -HALF_WIDTH - WALL_T / 2), HEIGHT, WALL_T,
             texture="concrete"),
        Wall((-WALL_T / 2, -HALF_WIDTH), (-WALL_T / 2, HALF_WIDTH), HEIGHT, WALL_T,
             texture="bricks_grey"),
        Wall((LENGTH + WALL_T / 2, -HALF_WIDTH), (LENGTH + WALL_T / 2, HALF_WIDTH), HEIGHT, WALL_T,
             texture="bricks_red"),
    )
    marks: list[Landmark] = []
    for side in (1, -1):
        marks.append(_on_wall(LENGTH / 2, side, LENGTH - 0.01, 0.1, 0.0, 0.02,
                              color=(0.15, 0.15, 0.17, 1.0), name=f"skirting{side:+d}"))
    doors = [(1.0, 1, "wood_dark"), (3.4, 1, "wood_light"), (5.9, 1, "wood_dark"),
             (2.2, -1, "wood_light"), (4.6, -1, "wood_dark"), (7.0, -1, "wood_light")]
    for i, (x, side, tex) in enumerate(doors):
        marks.append(_on_wall(x, side, 0.9, 2.0, 0.1, 0.05, color=WHITE, texture=tex,
                              name=f"door{i}"))
    posters = [(2.0, 1, "poster_a"), (4.4, 1, "stripes_warm"), (6.8, 1, "poster_b"),
               (0.9, -1, "poster_b"), (3.3, -1, "checker_green"), (5.6, -1, "poster_a")]
    for i, (x, side, tex) in enumerate(posters):
        marks.append(_on_wall(x, side, 0.6, 0.45, 0.35, 0.02, color=WHITE, texture=tex,
                              name=f"poster{i}"))
    for i, (x, side) in enumerate([(1.6, 1), (2.9, -1), (4.0, 1), (5.2, -1), (6.3, 1)]):
        marks.append(_on_wall(x, side, 0.25, 0.2, 0.55, 0.04, color=LAMP, name=f"lamp{i}"))
    marks += [
        Landmark((2.7, 0.72), radius=0.14, height=0.45, color=(0.2, 0.35, 0.6, 1.0),
                 name="bin"),
        Landmark((4.9, 0.68), shape="box", extent=(1.1, 0.4), height=0.42, color=WOOD,
                 texture="wood_light", name="bench"),
        Landmark((3.9, -0.8), radius=0.08, height=0.5, color=(0.85, 0.05, 0.05, 1.0),
                 name="extinguisher"),
        Landmark((6.6, -0.66), radius=0.18, height=0.35, color=(0.45, 0.3, 0.2, 1.0),
                 name="plant_pot"),
        Landmark((6.6, -0.66), radius=0.23, height=0.35, base=0.35,
                 color=(0.15, 0.5, 0.2, 1.0), name="plant"),
    ]
    return Scene(
        name="hallway",
        bounds=((0.0, -HALF_WIDTH), (LENGTH, HALF_WIDTH)),
        walls=walls,
        landmarks=tuple(marks),
        floor_color=(1.0, 1.0, 1.0, 1.0),
        floor_texture="floor_tiles",
        metadata={"route_origin": ROUTE_ORIGIN},
    )
