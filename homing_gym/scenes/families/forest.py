"""``forest``: a procedural forest, new every episode (drawn from the episode's random
generator, so ``reset(seed=...)`` reproduces it).

No walls: a fence (invisible, :attr:`Scene.fence`) keeps the robot on a 6-12 m square of
forest floor. On it stand 10-40 trunks (0.05-0.4 m radius, most of them thin, 5-10 m
tall, tapering, some leaning by up to 5 degrees) in a bark colour of the world's (brown,
grey, dark or birch-pale) varied per tree, under a canopy of leafy crowns from 2.5 m
up; undergrowth (low lumpy bushes 0.15-0.45 m high), ferns (fronds of thin triangles,
0.15-0.45 m) and 0-3 fallen logs (0.08-0.25 m radius, 1.2-3.5 m long, lying on the
ground). The ground is leaf litter out to 28 m: patches and specks between a dark and
a light tint of the world's brown to dark-green litter. Beyond the fence 120-200 more
trunks stand out to 24 m, and a band of dark trunks and canopy 25-27 m away closes the
view, so the far view is a wall of trunks that stays put while the robot moves. The robot
bumps into trunks, bushes and logs (kept :data:`~homing_gym.scenes.random_nature.GAP`
apart and off the fence, so all the floor is reachable), never into ferns, crowns,
ground or the far forest. Randomised: the square's size, every count, size, position,
lean and colour, and the world's :func:`~homing_gym.scenes.appearance.random_appearance`.
"""

from __future__ import annotations

import math

import numpy as np

from homing_gym.scenes.appearance import random_appearance
from homing_gym.scenes.base import Scene
from homing_gym.scenes.families.wild_parts import (Footprints, blades, cylinder, ground,
                                                   open_part, skyline, tubes,
                                                   unit_icosahedron)
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.random_nature import _lump, _part

#: Bark colours (RGB) a world draws its trunks around: brown, grey (beech), dark, birch.
BARKS = np.array([[0.36, 0.26, 0.16], [0.47, 0.45, 0.41], [0.22, 0.18, 0.14],
                  [0.78, 0.76, 0.70]])
#: Leaf litter from brown to dark green (RGB).
LITTER = (np.array([0.36, 0.25, 0.13]), np.array([0.20, 0.27, 0.11]))
#: How far out (metres) the trunks beyond the fence stand, and the far forest band.
FAR_TRUNKS, FAR_BAND = 24.0, (25.0, 27.0)


def _bark(rng: np.random.Generator, base: np.ndarray, faces: int) -> np.ndarray:
    """Face colours ``(faces, 3)`` of one trunk: ``base`` varied per tree by up to 20 %
    and per face by up to 10 % (streaks of bark)."""
    tree = base * rng.uniform(0.8, 1.2) * rng.uniform(0.93, 1.07, 3)
    return tree * rng.uniform(0.9, 1.1, (faces, 1))


def _crown(rng: np.random.Generator, xy, low: float, leaves: np.ndarray
           ) -> tuple[tuple[np.ndarray, np.ndarray], np.ndarray]:
    """A leafy crown (a lumpy flattened icosahedron 2.4-6 m across) whose bottom is
    ``low`` metres up over floor point ``xy``, and its colour (``leaves`` varied by 15 %)."""
    ball, faces = unit_icosahedron()
    radius = float(rng.uniform(1.2, 3.0))
    crown = ball * [radius, radius, radius * rng.uniform(0.5, 0.9)]
    crown *= rng.uniform(0.8, 1.2, (len(crown), 1))
    crown = crown + (xy[0], xy[1], low - crown[:, 2].min())
    return (crown, faces), leaves * rng.uniform(0.85, 1.15, 3)


def _far_trunks(rng: np.random.Generator, half: float, bark: np.ndarray
                ) -> tuple[MeshPart, np.ndarray]:
    """120-200 trunks (open 6-sided tubes, 0.08-0.45 m radius, 8-15 m tall) between the
    fence and :data:`FAR_TRUNKS` metres, each 0.3 m clear of the others, as one
    non-colliding part, and their floor points ``(N, 2)``."""
    n = int(rng.integers(120, 201))
    distance = rng.uniform(half + 0.8, FAR_TRUNKS, 3 * n)
    angle = rng.uniform(0, 2 * math.pi, 3 * n)
    xy = np.column_stack([distance * np.cos(angle), distance * np.sin(angle)])
    radius = 0.08 + 0.37 * rng.random(3 * n) ** 2
    kept: list[int] = []
    for i in np.flatnonzero(np.abs(xy).max(axis=1) > half + radius + 0.3):
        if len(kept) == n:
            break
        if not kept or np.all(np.hypot(*(xy[kept] - xy[i]).T) >= radius[kept] + radius[i] + 0.3):
            kept.append(i)
    triangles = tubes(xy[kept], rng.uniform(8.0, 15.0, len(kept)), radius[kept], 0.4)
    count = len(kept)
    tree = bark * rng.uniform(0.8, 1.2, (count, 1, 1)) * rng.uniform(0.93, 1.07, (count, 1, 3))
    colors = tree * rng.uniform(0.9, 1.1, (count, triangles.shape[1], 1))
    return open_part(triangles.reshape(-1, 3, 3), colors.reshape(-1, 3), "far_trunks"), xy[kept]


def forest_scene(rng: np.random.Generator) -> Scene:
    """Draw a ``forest`` world from ``rng`` (see the module doc)."""
    horizon, appearance = random_appearance(rng, outdoor=True)
    half = float(rng.uniform(3.0, 6.0))
    floor = Footprints(half)
    bark = BARKS[rng.integers(len(BARKS))] * rng.uniform(0.85, 1.15, 3)
    leaves = np.array([rng.uniform(0.1, 0.3), rng.uniform(0.3, 0.55), rng.uniform(0.05, 0.2)])
    litter = LITTER[0] + rng.uniform(0, 1) * (LITTER[1] - LITTER[0])
    litter = litter * rng.uniform(0.8, 1.2)

    trunks, trunk_colors, crowns, crown_colors = [], [], [], []
    for _ in range(int(rng.integers(10, 41))):
        radius = 0.05 + 0.35 * float(rng.random()) ** 2
        lean = float(rng.uniform(0.0, 0.09) if rng.random() < 0.4 else rng.uniform(0.0, 0.02))
        spot = floor.place(rng, radius + 0.35 * lean + 0.01)
        if spot is None:
            continue
        (x, y), height = spot[0], float(rng.uniform(5.0, 10.0))
        heading = rng.uniform(0, 2 * math.pi)
        top = (x + lean * height * math.cos(heading), y + lean * height * math.sin(heading))
        trunk = cylinder((x - 0.1 * lean * math.cos(heading), y - 0.1 * lean * math.sin(heading),
                          -0.1), (*top, height), radius, radius * rng.uniform(0.5, 0.8))
        trunks.append(trunk), trunk_colors.append(_bark(rng, bark, len(trunk[1])))
        if rng.random() < 0.7:
            crown, color = _crown(rng, top, rng.uniform(2.5, max(3.0, height - 2.0)), leaves)
            crowns.append(crown), crown_colors.append(color)

    logs, log_colors = [], []
    for _ in range(int(rng.integers(0, 4))):
        radius, length = float(rng.uniform(0.08, 0.25)), float(rng.uniform(1.2, 3.5))
        if (ends := floor.place(rng, radius + 0.01, length)) is not None:
            a, b = ends
            log = cylinder((*a, 0.85 * radius), (*b, 0.85 * radius), radius,
                           radius * rng.uniform(0.7, 1.0), sections=8)
            skin = np.array([0.25, 0.3, 0.15]) if rng.random() < 0.5 else bark * 0.8  # mossy
            logs.append(log), log_colors.append(_bark(rng, skin, len(log[1])))

    bushes, bush_colors = [], []
    for _ in range(int(rng.integers(4, 15))):
        size, height = rng.uniform(0.1, 0.35, 2), float(rng.uniform(0.15, 0.45))
        if (spot := floor.place(rng, float(size.max()) * 1.25)) is not None:
            bushes.append(_lump(rng, spot[0], (*size, height)))
            bush_colors.append(leaves * rng.uniform(0.6, 1.1) * rng.uniform(0.9, 1.1, 3))

    clumps = int(rng.integers(6, 21))
    fronds = rng.integers(5, 11, clumps)
    centres = np.repeat(rng.uniform(-half, half, (clumps, 2)), fronds, axis=0)
    ferns = blades(rng, centres + rng.uniform(-0.04, 0.04, centres.shape), (0.15, 0.45),
                   (0.04, 0.1), (0.5, 1.0))
    fern_colors = (np.repeat(leaves * rng.uniform(1.0, 1.4, (clumps, 1)), fronds, axis=0)
                   * rng.uniform(0.85, 1.15, (len(ferns), 1)))

    far, far_xy = _far_trunks(rng, half, bark)
    for xy in far_xy:
        if np.abs(xy).max() < half + 5.0 and rng.random() < 0.3:
            crown, color = _crown(rng, xy, rng.uniform(3.0, 7.0), leaves)
            crowns.append(crown), crown_colors.append(color)

    parts: list[MeshPart] = [
        ground(rng, litter * 0.6, np.minimum(litter * 1.4, 1.0)),
        skyline(rng, FAR_BAND, float(rng.uniform(7.0, 10.0)), float(rng.uniform(2.0, 4.0)), 0.9,
                (bark * 0.35, leaves * 0.45), "far_forest"),
        _part(trunks, trunk_colors, "trunks", True),
        far,
        _part(crowns, crown_colors, "crowns", False),
        open_part(ferns, fern_colors, "ferns"),
    ]
    if bushes:
        parts.append(_part(bushes, bush_colors, "undergrowth", True))
    if logs:
        parts.append(_part(logs, log_colors, "logs", True))
    return Scene(name="forest", bounds=((-half, -half), (half, half)), meshes=tuple(parts),
                 fence=True, ground_plane=False, sky_color=horizon, appearance=appearance)
