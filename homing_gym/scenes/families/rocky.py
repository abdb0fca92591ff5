"""``rocky``: procedural rocky terrain, new every episode (drawn from the episode's random
generator, so ``reset(seed=...)`` reproduces it).

No walls: a fence (invisible, :attr:`Scene.fence`) keeps the robot on a 6-12 m square of
gravel and bare rock. On it lie 1-4 outcrops (clusters of 3-6 large overlapping boulders
up to 1.35 m high, or 1-3 thick tilted rock slabs 1-3 m long side by side, like strata
breaking the surface) and 8-30 boulders of many sizes (0.1-1.5 m across, log-uniform,
so most are small), each an angular solid (a lumpy ball shaved by 0-3 fracture planes)
in the world's grey-brown rock tint varied per rock; flat patches of bare rock (0.5-2 m)
and 3-8 small tufts of dry grass (thin blades 0.08-0.35 m tall). The gravel ground
reaches 28 m out, in patches and specks of the rock tint. Beyond the fence lie bigger
boulders (0.6-4 m) out to 14 m, a jagged ridge 15-19 m away (1.5-9 m high) and a range of
mountains 23-25.5 m away (3-14 m high, hazed towards the sky's colour): a skyline that
stays put while the robot moves. The robot bumps into outcrops and boulders (kept
:data:`~homing_gym.scenes.random_nature.GAP` apart and off the fence, so all the floor is
reachable), never into the rock patches, tufts, ground or anything beyond the fence.
Randomised: the square's size, every count, size, shape, position and colour, and the
world's :func:`~homing_gym.scenes.appearance.random_appearance`.
"""

from __future__ import annotations

import math

import numpy as np

from homing_gym.scenes.appearance import random_appearance
from homing_gym.scenes.base import Scene
from homing_gym.scenes.families.wild_parts import (Footprints, Mesh, blades, ground,
                                                   open_part, reach, rock, skyline)
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.random_nature import _part, _unit_ball

#: Rock colours (RGB) a world's tint lies between: grey and brown.
ROCK = (np.array([0.52, 0.51, 0.49]), np.array([0.55, 0.44, 0.33]))
#: Reach (metres) of the boulders beyond the fence, the ridge and the mountains.
FAR_BOULDERS, RIDGE, MOUNTAINS = 14.0, (15.0, 19.0), (23.0, 25.5)


def _boulder(rng: np.random.Generator, across: float) -> Mesh:
    """A boulder about ``across`` metres wide (x and y half sizes 0.35-0.5 of it, height
    0.4-0.9 of its width) on the floor at the origin, shaved by 0-3 fracture planes."""
    size = (across * rng.uniform(0.35, 0.5), across * rng.uniform(0.35, 0.5),
            across * rng.uniform(0.2, 0.45))
    return rock(rng, (0.0, 0.0), size, int(rng.integers(0, 4)))


def _slab(rng: np.random.Generator, offset: float, yaw: float, dip: float) -> Mesh:
    """A rock slab 1-3 m long, 0.6-1.5 m wide and 0.3-0.8 m thick (a flat angular rock,
    :func:`~homing_gym.scenes.families.wild_parts.rock`) turned to ``yaw``, tilted by
    ``dip`` radians about its length, ``offset`` metres across it from the origin and
    sunk until its underside is at most 5 cm above the floor: a tilted stratum breaking
    the surface, no overhang to drive under."""
    size = (rng.uniform(0.5, 1.5), rng.uniform(0.3, 0.75), rng.uniform(0.15, 0.4))
    across = (-math.sin(yaw) * offset, math.cos(yaw) * offset)
    vertices, faces = rock(rng, across, size, int(rng.integers(1, 4)), tilt=dip, yaw=yaw,
                           sink=0.0)
    underside = _unit_ball()[0][:, 2] < -0.5
    vertices[:, 2] -= vertices[underside, 2].max() - 0.05
    return vertices, faces


def _outcrop(rng: np.random.Generator) -> list[Mesh]:
    """An outcrop about the origin: a large boulder (1-1.5 m across) in the middle and
    2-5 more (0.6-1.3 m) overlapping it from all round (no hollow in between), or 1-3
    parallel slabs (:func:`_slab`) side by side."""
    if rng.random() < 0.6:
        members = [_boulder(rng, float(rng.uniform(1.0, 1.5)))]
        for _ in range(int(rng.integers(2, 6))):
            vertices, faces = _boulder(rng, float(rng.uniform(0.6, 1.3)))
            r, a = rng.uniform(0.2, 0.6), rng.uniform(0, 2 * math.pi)
            members.append((vertices + [r * math.cos(a), r * math.sin(a), 0.0], faces))
        return members
    yaw, dip = float(rng.uniform(0, 2 * math.pi)), float(rng.uniform(0.1, 0.45))
    steps = int(rng.integers(1, 4))
    return [_slab(rng, 0.8 * (k - (steps - 1) / 2), yaw, dip) for k in range(steps)]


def _rock_colors(rng: np.random.Generator, tint: np.ndarray, meshes: list[Mesh]) -> list:
    """Face colours of each rock: ``tint`` varied per rock by up to 20 % (and its hue a
    little) and per face by up to 8 %."""
    return [tint * rng.uniform(0.8, 1.2) * rng.uniform(0.94, 1.06, 3)
            * rng.uniform(0.92, 1.08, (len(faces), 1)) for _, faces in meshes]


def _patches(rng: np.random.Generator, half: float, tint: np.ndarray) -> tuple:
    """3-8 flat patches of bare rock (irregular 9-gons 0.5-2 m across, 1 cm above the
    floor, lighter or darker than ``tint``): their triangles ``(F, 3, 3)`` and colours."""
    triangles, colors = [], []
    for _ in range(int(rng.integers(3, 9))):
        centre = rng.uniform(-half, half, 2)
        a = np.sort(rng.uniform(0, 2 * math.pi, 9))
        r = rng.uniform(0.25, 1.0) * rng.uniform(0.6, 1.0, 9)
        rim = np.column_stack([centre[0] + r * np.cos(a), centre[1] + r * np.sin(a),
                               np.full(9, 0.01)])
        middle = np.array([*centre, 0.01])
        triangles += [[middle, rim[k], rim[(k + 1) % 9]] for k in range(9)]
        colors += [tint * rng.uniform(0.75, 1.25)] * 9
    colors = np.array(colors) * rng.uniform(0.95, 1.05, (len(colors), 1))
    return np.array(triangles), colors


def rocky_scene(rng: np.random.Generator) -> Scene:
    """Draw a ``rocky`` world from ``rng`` (see the module doc)."""
    horizon, appearance = random_appearance(rng, outdoor=True)
    half = float(rng.uniform(3.0, 6.0))
    floor = Footprints(half)
    tint = (ROCK[0] + rng.uniform(0, 1) * (ROCK[1] - ROCK[0])) * rng.uniform(0.75, 1.2)

    rocks: list[Mesh] = []
    for _ in range(int(rng.integers(1, 5))):
        members = _outcrop(rng)
        extent = max(reach(vertices, (0.0, 0.0)) for vertices, _ in members)
        if (spot := floor.place(rng, extent)) is not None:
            rocks += [(vertices + [*spot[0], 0.0], faces) for vertices, faces in members]
    for _ in range(int(rng.integers(8, 31))):
        vertices, faces = _boulder(rng, float(math.exp(rng.uniform(math.log(0.1), math.log(1.5)))))
        if (spot := floor.place(rng, reach(vertices, (0.0, 0.0)))) is not None:
            rocks.append((vertices + [*spot[0], 0.0], faces))

    far: list[Mesh] = []
    beyond = Footprints(half, gap=0.5)
    for _ in range(int(rng.integers(10, 26))):
        size = float(rng.uniform(0.6, 4.0))
        if (spot := beyond.place(rng, 0.5 * size, inside=False, far=FAR_BOULDERS)) is not None:
            far.append(rock(rng, spot[0], (0.5 * size * rng.uniform(0.6, 1.0),
                                           0.5 * size * rng.uniform(0.6, 1.0),
                                           0.5 * size * rng.uniform(0.3, 0.8)),
                            0, coarse=True))

    tufts = int(rng.integers(3, 9))
    count = rng.integers(8, 21, tufts)
    feet = np.repeat(rng.uniform(-half, half, (tufts, 2)), count, axis=0)
    grass = blades(rng, feet + rng.uniform(-0.05, 0.05, feet.shape), (0.08, 0.35),
                   (0.01, 0.03), (0.1, 0.4))
    dry = np.array([rng.uniform(0.45, 0.65), rng.uniform(0.5, 0.65), rng.uniform(0.15, 0.3)])
    grass_colors = dry * rng.uniform(0.7, 1.2, (len(grass), 1))

    sky = np.asarray(horizon)
    haze = float(rng.uniform(0.3, 0.6))                 # how far the mountains fade to sky
    mountain = tint * (1 - haze) + sky * haze
    parts: list[MeshPart] = [
        ground(rng, tint * 0.6, np.minimum(tint * 1.25, 1.0)),
        skyline(rng, RIDGE, float(rng.uniform(1.5, 3.0)), float(rng.uniform(2.0, 6.0)),
                float(rng.uniform(0.6, 0.9)), (tint * 0.6, tint * 0.75), "ridge"),
        skyline(rng, MOUNTAINS, float(rng.uniform(3.0, 5.0)), float(rng.uniform(3.0, 9.0)),
                float(rng.uniform(0.5, 0.9)), (mountain * 0.85, mountain), "mountains", n=180),
        _part(rocks, _rock_colors(rng, tint, rocks), "rocks", True),
        _part(far, _rock_colors(rng, tint, far), "far_rocks", False),
        open_part(*_patches(rng, half, tint), "rock_patches"),
        open_part(grass, grass_colors, "tufts"),
    ]
    return Scene(name="rocky", bounds=((-half, -half), (half, half)), meshes=tuple(parts),
                 fence=True, ground_plane=False, sky_color=horizon, appearance=appearance)
