"""``random_arena``: the arena's 2.4 m square with a new world every episode.

3-8 landmarks of random shape (cylinder or box), size, colour, texture and position
(non-overlapping, at least 0.45 m of clearance between footprints so the robot fits
between them), and random walls and floor, all drawn from the episode's random generator.
Each wall and the floor is textured or, with probability ``PLAIN_PROBABILITY``, a plain
random colour (walls pale, floor grey), so that plain rooms like the ``arena`` are part of
the distribution. Made for training policies that generalise to unseen scenes.
"""

from __future__ import annotations

import numpy as np

from homing_gym.scenes.arena import ARENA_SIDE
from homing_gym.scenes.base import Landmark, Scene, Wall, square_walls

WALL_TEXTURES = ("bricks_red", "bricks_grey", "stripes_warm", "stripes_cool", "checker_green",
                 "checker_dark", "wood_light", "wood_dark", "poster_a", "poster_b", "concrete")
FLOOR_TEXTURES = ("floor_tiles", "concrete", "wood_light", "wood_dark", "checker_dark")
LANDMARK_TEXTURES = (None, None, "stripes_warm", "stripes_cool", "checker_green", "poster_a",
                     "poster_b", "bricks_red")
CLEARANCE = 0.45
PLAIN_PROBABILITY = 0.3


def random_arena_scene(rng: np.random.Generator) -> Scene:
    """Draw a ``random_arena`` world from ``rng``."""
    half = ARENA_SIDE / 2
    count = int(rng.integers(3, 9))
    landmarks: list[Landmark] = []
    while len(landmarks) < count:
        shape = "cylinder" if rng.random() < 0.5 else "box"
        radius = float(rng.uniform(0.05, 0.2))
        extent = (float(rng.uniform(0.1, 0.4)), float(rng.uniform(0.1, 0.4)))
        reach = radius if shape == "cylinder" else float(np.hypot(*extent) / 2)
        margin = half - reach - 0.05
        pos = (float(rng.uniform(-margin, margin)), float(rng.uniform(-margin, margin)))
        if any(np.hypot(pos[0] - o.position[0], pos[1] - o.position[1])
               < reach + o.footprint_radius + CLEARANCE for o in landmarks):
            continue
        color = tuple(float(c) for c in rng.uniform(0.05, 1.0, 3)) + (1.0,)
        landmarks.append(Landmark(
            position=pos, shape=shape, radius=radius, extent=extent,
            height=float(rng.uniform(0.15, 0.8)), yaw=float(rng.uniform(-np.pi, np.pi)),
            color=color, texture=LANDMARK_TEXTURES[rng.integers(len(LANDMARK_TEXTURES))],
            name=f"landmark{len(landmarks)}"))
    walls = tuple(
        Wall(w.start, w.end, height=w.height, thickness=w.thickness,
             **_surface(rng, WALL_TEXTURES, low=0.7, high=1.0))
        for w in square_walls(ARENA_SIDE, height=0.6))
    floor = _surface(rng, FLOOR_TEXTURES, low=0.3, high=0.8)
    return Scene(
        name="random_arena",
        bounds=((-half, -half), (half, half)),
        walls=walls,
        landmarks=tuple(landmarks),
        floor_color=floor["color"],
        floor_texture=floor["texture"],
    )


def _surface(rng: np.random.Generator, textures: tuple[str, ...], low: float,
             high: float) -> dict:
    """``color`` and ``texture`` of a wall or floor: a texture from ``textures`` on white,
    or (with ``PLAIN_PROBABILITY``) no texture and a near-grey colour of brightness in
    ``[low, high]``."""
    if rng.random() < PLAIN_PROBABILITY:
        grey = rng.uniform(low, high) + rng.uniform(-0.05, 0.05, 3)
        return {"color": tuple(float(c) for c in np.clip(grey, 0, 1)) + (1.0,),
                "texture": None}
    return {"color": (1.0, 1.0, 1.0, 1.0), "texture": str(textures[rng.integers(len(textures))])}
