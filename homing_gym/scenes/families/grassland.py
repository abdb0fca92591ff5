"""``grassland``: open grass, a new world every episode (drawn from the episode's random
generator, so ``reset(seed=...)`` reproduces it).

No walls: a fence (invisible, :attr:`Scene.fence`) keeps the robot on a 6-8 m square.
Grass covers it and 0.5 m beyond: 7,000-9,500 thin triangular blades, drawn in tussocks
(:func:`~homing_gym.scenes.tussocks.tussock_blades`) and spread out by up to 0.2-0.4 m
(from clumpy to an even meadow), 5 cm up to 25-60 cm tall, 1.5-12 cm wide at the foot,
green to straw-coloured, none rooted well inside a shrub, rock or trunk: 75-165 blades a
square metre, the budget that keeps stepping fast. The robot drives through the grass; a
camera a few centimetres up (an ant's eye) sees blades in front of nearly all the
horizon and in about half the view down to 10 degrees below it, the bare ground between
them further down. On the grass stand 2-6 shrubs (green lumps 0.3-0.8 m across, 0.3-0.9
m high), 0-4 rocks (grey lumps 0.16-0.6 m across and high) and sometimes a tree
(random_nature's); the robot bumps into those (their solid cross-section at its height,
:mod:`homing_gym.scenes.footprint`), never into blades, crowns, ground or hills. The
ground disc reaches 28 m, tinted from sand to green; beyond the fence stand 6-16 trees
up to 12 m out, and a low ring of hills (0.4-0.75 of random_nature's height) 18-26 m away
gives a horizon that stays put. Drawn per world: size, blade count, spread, height, width
and colour, the objects' places, sizes and colours, the ground's tint and the world's
appearance (:func:`~homing_gym.scenes.appearance.random_appearance`, outdoors).
"""

from __future__ import annotations

import numpy as np

from homing_gym.scenes.appearance import random_appearance
from homing_gym.scenes.base import Scene
from homing_gym.scenes.families.open_land import Spots, tinted_ground
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.random_nature import _hills, _lump, _part, _tree
from homing_gym.scenes.tussocks import tussock_blades

#: Ground tints (RGB) a world's lies between: bare sand, lush green.
SAND, GREEN = np.array([0.72, 0.63, 0.43]), np.array([0.3, 0.5, 0.2])
#: Straw (RGB): the colour dry blades fade to.
STRAW = np.array([0.78, 0.7, 0.42])
#: Fewest and most blades a world holds.
BLADES = (7_000, 9_500)
#: How far grass reaches beyond the fence (metres).
GRASS_MARGIN = 0.5


def grass_blades(rng: np.random.Generator, reach: float, clear_of: np.ndarray) -> MeshPart:
    """:data:`BLADES` tussock blades (:func:`tussock_blades`, seeded from ``rng``) in
    clumps within ``reach`` metres of the origin in x and y, each blade moved by up to
    0.2-0.4 m in x and y, widened 1.5-3 times, 5 cm to 25-60 cm tall, its green faded
    by up to 70 % towards :data:`STRAW`, less those rooted inside 0.7 of a circle of
    ``clear_of`` (rows x, y, radius in metres: the solids' footprints); a non-colliding
    part of open triangles."""
    count = int(rng.integers(*BLADES, endpoint=True))
    corners, colors = tussock_blades(count, int(rng.integers(2**31)), reach)
    corners[..., :2] += rng.uniform(-1, 1, (count, 1, 2)) * rng.uniform(0.2, 0.4)
    feet = corners[:, :2].mean(axis=1, keepdims=True)              # (n, 1, 3)
    corners[:, :2] = feet + (corners[:, :2] - feet) * rng.uniform(1.5, 3.0)
    height = corners[:, 2, 2]                       # 0.05-0.9 m as tussock_blades draws it
    top = rng.uniform(0.25, 0.6)
    scale = (0.05 + (height - 0.05) * (top - 0.05) / 0.85) / height
    corners[:, 2] = feet[:, 0] + (corners[:, 2] - feet[:, 0]) * scale[:, None]
    dry = rng.uniform(0.0, 0.7) * rng.uniform(0.5, 1.0, (count, 1))
    colors = ((1 - dry) * colors + dry * STRAW) * rng.uniform(0.8, 1.1)
    gaps = np.linalg.norm(feet[:, :, None, :2] - clear_of[None, None, :, :2], axis=3)[:, 0]
    keep = np.all(gaps >= 0.7 * clear_of[:, 2], axis=1)
    return MeshPart(corners[keep].reshape(-1, 3), np.arange(3 * keep.sum()).reshape(-1, 3),
                    np.clip(colors[keep], 0, 1), collision=False, name="grass",
                    solid_faces=())


def grassland_scene(rng: np.random.Generator) -> Scene:
    """Draw a ``grassland`` world from ``rng`` (see the module doc)."""
    horizon, appearance = random_appearance(rng, outdoor=True)
    half = float(rng.uniform(3.0, 4.0))
    spots = Spots(rng, half, half)
    solids, solid_colors = [], []
    for _ in range(int(rng.integers(2, 7))):              # shrubs
        size = rng.uniform(0.15, 0.4, 2)
        if (xy := spots.inside(float(size.max()) * 1.25)) is not None:
            solids.append(_lump(rng, xy, (*size, rng.uniform(0.15, 0.45))))
            solid_colors.append([rng.uniform(0.1, 0.3), rng.uniform(0.3, 0.55),
                                 rng.uniform(0.05, 0.2)])
    for _ in range(int(rng.integers(0, 5))):              # rocks
        size = rng.uniform(0.08, 0.3, 2)
        if (xy := spots.inside(float(size.max()) * 1.25)) is not None:
            solids.append(_lump(rng, xy, (*size, rng.uniform(0.08, 0.3))))
            solid_colors.append(np.full(3, rng.uniform(0.4, 0.7)) * rng.uniform(0.9, 1.1, 3))
    trunks, bark, crowns, leaves = [], [], [], []
    inside_trees = int(rng.random() < 0.4)
    for k in range(inside_trees + int(rng.integers(6, 17))):
        xy = spots.inside(0.15) if k < inside_trees else spots.beyond(0.15, half + 12.0)
        if xy is not None:
            (trunk, crown), (trunk_color, crown_color) = _tree(rng, xy)
            trunks.append(trunk), bark.append(trunk_color)
            crowns.append(crown), leaves.append(crown_color)
    ground = tinted_ground(rng, SAND + (GREEN - SAND) * rng.uniform(0.0, 1.0))
    hills = _hills(rng)
    hill_vertices = hills.vertices * [1.0, 1.0, rng.uniform(0.4, 0.75)]
    parts = [ground, MeshPart(hill_vertices, hills.faces, hills.face_colors, collision=False,
                              name="hills", solid_faces=()),
             grass_blades(rng, half + GRASS_MARGIN, np.reshape(spots.placed, (-1, 3)))]
    if trunks:
        parts += [_part(trunks, bark, "trunks", True), _part(crowns, leaves, "crowns", False)]
    if solids:
        parts.append(_part(solids, solid_colors, "shrubs_and_rocks", True))
    return Scene(name="grassland", bounds=((-half, -half), (half, half)), meshes=tuple(parts),
                 fence=True, ground_plane=False, sky_color=horizon, appearance=appearance)
