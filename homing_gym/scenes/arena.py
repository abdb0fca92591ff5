"""``arena``: the Yu & Kim (2011) test arena.

A 2.4 m square with walls and four red cylinders of radius 10.75 cm and height 38.5 cm
(Yu & Kim §IV). The paper gives sizes but not positions; we place the cylinders as in
its Fig. 7(b): an irregular quadrilateral spread around the arena centre, 0.45-0.65 m
from it, so that no two bearings coincide from most places and every cylinder stays
visible from the whole floor.
"""

from __future__ import annotations

from homing_gym.scenes.base import Landmark, Scene, square_walls

ARENA_SIDE = 2.4
RED = (0.85, 0.08, 0.08, 1.0)
CYLINDER_POSITIONS = ((0.45, 0.35), (-0.35, 0.55), (-0.55, -0.25), (0.30, -0.50))


def arena_scene() -> Scene:
    """The fixed ``arena`` scene: walls of plain light paint, grey floor."""
    half = ARENA_SIDE / 2
    landmarks = tuple(
        Landmark(position=pos, shape="cylinder", radius=0.1075, height=0.385, color=RED,
                 name=f"cylinder{i}")
        for i, pos in enumerate(CYLINDER_POSITIONS))
    return Scene(
        name="arena",
        bounds=((-half, -half), (half, half)),
        walls=square_walls(ARENA_SIDE, height=0.5, color=(0.93, 0.93, 0.9, 1.0)),
        landmarks=landmarks,
        floor_color=(0.6, 0.6, 0.6, 1.0),
    )
