"""``desert``: sparse scrub on sand, a new world every episode (drawn from the episode's
random generator, so ``reset(seed=...)`` reproduces it).

No walls: a fence (invisible, :attr:`Scene.fence`) keeps the robot on a 6-12 m square
of sand. On it stand few things, far apart: 1-5 scrub bushes (low lumps 0.12-0.4 m high,
olive, grey-green or dry brown), 0-3 rocks (lumps 0.16-0.6 m high) and 0-3 cacti
(stems 0.04-0.1 m in radius and 0.4-1.3 m tall, some with one or two arms) or, in other
worlds, dead bushes (4-7 bare twigs of 1-2 cm, 0.2-0.6 m long, splayed out); 4-12 more of
them stand beyond the fence, up to 10.5 m from the middle. The robot bumps into all of
them (their solid cross-section at its height, :mod:`homing_gym.scenes.footprint`),
never into the ground, its gravel patches or the horizon. The ground disc reaches 28 m,
tinted between yellow, orange and grey sand, with 0-4 flat darker gravel patches
(0.4-1.8 m across). The skyline is the landmark a desert ant steers by: in most worlds
a ring of dunes (0.2-1.6 m high) 11.5-15 m out, 0-4 layered mesas and buttes (1.5-4.3 m
high) 14-27 m out, and always a mountain range (peaks up to 9 m) 23.5-27 m out, the
far ones hazed towards the sky's colour. Drawn per world: size, counts, places, sizes and
colours of everything, the skyline, and the world's appearance
(:func:`~homing_gym.scenes.appearance.random_appearance`, outdoors).
"""

from __future__ import annotations

import math
from functools import partial
from typing import Callable

import numpy as np

from homing_gym.scenes.appearance import random_appearance
from homing_gym.scenes.base import Scene
from homing_gym.scenes.families.open_land import Mesh, Spots, rod, skyline_band, tinted_ground
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.random_nature import _lump, _part

#: Sand tints (RGB) a world's ground mixes: yellow, orange, grey.
SANDS = np.array([[0.86, 0.74, 0.5], [0.82, 0.56, 0.36], [0.62, 0.6, 0.55]])
#: Scrub colours (RGB): olive, grey-green, dry brown.
SCRUB = np.array([[0.42, 0.45, 0.25], [0.45, 0.5, 0.4], [0.5, 0.42, 0.3]])
#: Rock colours of mesas (RGB): red, tan, grey-violet.
MESA_ROCK = np.array([[0.7, 0.4, 0.28], [0.75, 0.58, 0.4], [0.6, 0.48, 0.45]])
#: Farthest (metres from the middle) that near objects stand beyond the fence; the dunes
#: begin beyond it.
OBJECT_REACH = 10.5
Spot = Callable[[float], "tuple[float, float] | None"]
Solids = list[tuple[Mesh, np.ndarray]]


def _scrub(rng: np.random.Generator, spot: Spot) -> Solids:
    """A scrub bush: a low lump 0.24-0.6 m across, 0.12-0.4 m high (none if ``spot``
    finds no room)."""
    size = rng.uniform(0.12, 0.3, 2)
    if (xy := spot(float(size.max()) * 1.25)) is None:
        return []
    color = SCRUB[rng.integers(len(SCRUB))] * rng.uniform(0.8, 1.15, 3)
    return [(_lump(rng, xy, (*size, rng.uniform(0.06, 0.2))), color)]


def _rock(rng: np.random.Generator, spot: Spot) -> Solids:
    """A rock: a lump 0.16-0.7 m across, 0.16-0.6 m high, reddish to grey."""
    size = rng.uniform(0.08, 0.35, 2)
    if (xy := spot(float(size.max()) * 1.25)) is None:
        return []
    color = np.array([0.55, 0.45, 0.4]) * rng.uniform(0.7, 1.3) * rng.uniform(0.9, 1.1, 3)
    return [(_lump(rng, xy, (*size, rng.uniform(0.08, 0.3))), color)]


def _cactus(rng: np.random.Generator, spot: Spot) -> Solids:
    """A cactus: a stem 0.04-0.1 m in radius, 0.4-1.3 m tall, and 0-2 arms (a short
    horizontal rod 0.1-0.2 m long, then one upright)."""
    radius, height = rng.uniform(0.04, 0.1), rng.uniform(0.4, 1.3)
    arms, reach = int(rng.integers(0, 3)), rng.uniform(0.1, 0.2)
    if (xy := spot(radius + (reach + radius if arms else 0.0))) is None:
        return []
    x, y = xy
    green = np.array([rng.uniform(0.2, 0.4), rng.uniform(0.42, 0.6), rng.uniform(0.2, 0.35)])
    meshes = [rod((x, y, -0.02), (x, y, height), radius)]
    angle = rng.uniform(0, 2 * math.pi)
    for k in range(arms):
        a = angle + k * math.pi + rng.uniform(-0.4, 0.4)
        thick, z = radius * rng.uniform(0.6, 0.8), height * rng.uniform(0.35, 0.6)
        elbow = np.array([x + reach * math.cos(a), y + reach * math.sin(a), z])
        meshes.append(rod((x, y, z), elbow, thick))
        top = elbow + (0, 0, height * rng.uniform(0.15, 0.4))
        meshes.append(rod(elbow - (0, 0, thick), top, thick))
    return [(m, green * rng.uniform(0.9, 1.1)) for m in meshes]


def _dead_bush(rng: np.random.Generator, spot: Spot) -> Solids:
    """A dead bush: 4-7 bare twigs 6-12 mm in radius and 0.2-0.6 m long from one foot,
    splayed 0.2-0.7 rad from upright."""
    length = rng.uniform(0.2, 0.6)
    if (xy := spot(length * math.sin(0.7) + 0.012)) is None:
        return []
    gray = np.array([0.45, 0.38, 0.3]) * rng.uniform(0.7, 1.3)
    twigs = []
    for _ in range(int(rng.integers(4, 8))):
        a, tilt = rng.uniform(0, 2 * math.pi), rng.uniform(0.2, 0.7)
        reach = length * rng.uniform(0.6, 1.0)
        tip = (xy[0] + reach * math.sin(tilt) * math.cos(a),
               xy[1] + reach * math.sin(tilt) * math.sin(a), reach * math.cos(tilt))
        twigs.append((rod((*xy, -0.01), tip, rng.uniform(0.006, 0.012)), gray))
    return twigs


def _gravel(rng: np.random.Generator, sand: np.ndarray, count: int, reach: float) -> MeshPart:
    """``count`` flat patches of gravel 3 mm above the ground within ``reach`` metres of
    the middle: fans of 8-12 triangles 0.4-1.8 m across, darker and greyer than ``sand``."""
    vertices, faces, colors, start = [], [], [], 0
    for _ in range(count):
        m, r = int(rng.integers(8, 13)), rng.uniform(0.2, 0.9)
        a = np.sort(rng.uniform(0, 2 * math.pi, m))
        ring = r * rng.uniform(0.7, 1.3, m)
        centre = rng.uniform(-reach, reach, 2)
        vertices.append(np.vstack([[*centre, 0.003], np.column_stack(
            [centre[0] + ring * np.cos(a), centre[1] + ring * np.sin(a), np.full(m, 0.003)])]))
        k = np.arange(m)
        faces.append(start + np.column_stack([np.zeros(m, int), 1 + k, 1 + (k + 1) % m]))
        start += m + 1
        gray = (0.5 * sand + 0.5 * sand.mean()) * rng.uniform(0.55, 0.8)
        colors.append(gray * rng.uniform(0.9, 1.1, (m, 1)))
    return MeshPart(np.vstack(vertices), np.vstack(faces), np.clip(np.vstack(colors), 0, 1),
                    collision=False, name="gravel", solid_faces=())   # open surfaces


def _mesa(rng: np.random.Generator, radius: float, height: float,
          rock: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A mesa or butte about the origin: a talus slope 1.2-1.4 times wider at its foot
    than its cliff, rising to 0.2-0.35 of ``height`` (metres), then a sheer cliff of 2-4
    strata in shades of ``rock`` and a flat top; its outline of 14 corners ``radius``
    metres (+- 20 %) out, stretched up to 1.5 times one way. Returns vertices, faces
    wound outwards (sides and top, no bottom) and face colours."""
    m = 14
    a = np.linspace(0, 2 * math.pi, m, endpoint=False)
    stretch, turn = rng.uniform(1.0, 1.5), rng.uniform(0, math.pi)
    r = radius * rng.uniform(0.8, 1.2, m)
    local = np.column_stack([r * np.cos(a) * stretch, r * np.sin(a)])
    c, s = math.cos(turn), math.sin(turn)
    outline = local @ np.array([[c, s], [-s, c]])
    strata = int(rng.integers(2, 5))
    talus = height * rng.uniform(0.2, 0.35)
    levels = np.concatenate([[0.0], talus + (height - talus) * np.arange(strata + 1) / strata])
    scales = np.concatenate([[rng.uniform(1.2, 1.4)], np.linspace(1.0, 0.96, strata + 1)])
    rings = [np.column_stack([outline * sc, np.full(m, z)]) for z, sc in zip(levels, scales)]
    vertices = np.vstack(rings + [[[0.0, 0.0, height]]])
    k = np.arange(m)
    k1 = (k + 1) % m
    faces, colors = [], []
    shades = [rock * rng.uniform(0.75, 1.15) for _ in range(len(levels) - 1)]
    for level, shade in enumerate(shades):
        low, high = level * m, (level + 1) * m
        faces += [np.column_stack([low + k, low + k1, high + k1]),
                  np.column_stack([low + k, high + k1, high + k])]
        colors += [np.tile(shade, (2 * m, 1))]
    top = len(levels) - 1
    faces.append(np.column_stack([np.full(m, len(vertices) - 1), top * m + k, top * m + k1]))
    colors.append(np.tile(rock * rng.uniform(0.9, 1.1), (m, 1)))
    return vertices, np.vstack(faces), np.vstack(colors)


def _mesas(rng: np.random.Generator, count: int, haze: np.ndarray) -> MeshPart:
    """``count`` mesas and buttes (:func:`_mesa`) 1-2.2 m in radius and 1-1.7 m plus
    0.5-1.2 times their radius high, at azimuths at least 0.5 rad apart, each as far out
    as keeps its foot 14-16 m from the middle (beyond the dunes) and within 27.1 m, their
    rock hazed 20-35 % towards ``haze`` (the sky at the horizon)."""
    vertices, faces, colors, start = [], [], [], 0
    azimuths: list[float] = []
    while len(azimuths) < count:
        a = rng.uniform(0, 2 * math.pi)
        if all(abs((a - b + math.pi) % (2 * math.pi) - math.pi) >= 0.5 for b in azimuths):
            azimuths.append(a)
    for a in azimuths:
        rock = MESA_ROCK[rng.integers(len(MESA_ROCK))] * rng.uniform(0.85, 1.15, 3)
        mix = rng.uniform(0.2, 0.35)
        radius = rng.uniform(1.0, 2.2)
        height = rng.uniform(1.0, 1.7) + radius * rng.uniform(0.5, 1.2)
        v, f, c = _mesa(rng, radius, height, rock)
        d = rng.uniform(14.0, 16.0) + np.hypot(v[:, 0], v[:, 1]).max()
        v = v + [d * math.cos(a), d * math.sin(a), 0.0]
        vertices.append(v), faces.append(f + start), colors.append((1 - mix) * c + mix * haze)
        start += len(v)
    return MeshPart(np.vstack(vertices), np.vstack(faces), np.clip(np.vstack(colors), 0, 1),
                    collision=False, name="mesas", solid_faces=())   # no bottoms


def _dunes(rng: np.random.Generator, sand: np.ndarray) -> MeshPart:
    """A ring of dunes, its foot 11.5-13 m out: a sloping band (its top 10-20 % farther
    out than its foot) 0.2-1.6 m high along a smooth irregular crest, in shades of
    ``sand``."""
    n = 96
    a = np.linspace(0, 2 * math.pi, n, endpoint=False)
    crest = sum(rng.uniform(0.2, 1.0) / k * np.cos(k * a + rng.uniform(0, 2 * math.pi))
                for k in range(2, 9))
    crest = 0.2 + (crest - crest.min()) / np.ptp(crest) * rng.uniform(0.5, 1.4)
    colors = sand * rng.uniform(0.85, 1.1) * rng.uniform(0.93, 1.07, (n, 1))
    return skyline_band(rng.uniform(11.5, 13.0), crest, colors, "dunes",
                        lean=rng.uniform(0.1, 0.2))


def _mountains(rng: np.random.Generator, haze: np.ndarray) -> MeshPart:
    """A mountain range 23.5-27 m out (its distance waving smoothly round): a low ridge
    all round (0.3-1 m high, rising and falling by 0.5-2 m more) with 3-8 sharp peaks
    1.5-6 m above it, rocky colours hazed 40-65 % towards ``haze``."""
    n = 180
    a = np.linspace(0, 2 * math.pi, n, endpoint=False)
    ridge = sum(rng.uniform(0.2, 1.0) / k * np.cos(k * a + rng.uniform(0, 2 * math.pi))
                for k in range(1, 7))
    ridge = (ridge - ridge.min()) / np.ptp(ridge)
    base = rng.uniform(0.3, 1.0) + ridge * rng.uniform(0.5, 2.0)
    heights = base
    for _ in range(int(rng.integers(3, 9))):
        gap = np.abs((a - rng.uniform(0, 2 * math.pi) + math.pi) % (2 * math.pi) - math.pi)
        peak = rng.uniform(1.5, 6.0) * np.maximum(0.0, 1 - gap / rng.uniform(0.08, 0.35))
        heights = np.maximum(heights, base + peak)
    rock = MESA_ROCK[rng.integers(len(MESA_ROCK))] * rng.uniform(0.6, 0.9)
    mix = rng.uniform(0.4, 0.65)
    colors = ((1 - mix) * rock + mix * haze) * rng.uniform(0.92, 1.08, (n, 1))
    distance = rng.uniform(24.5, 26.0) + rng.uniform(0.3, 1.0) * np.cos(
        rng.integers(1, 5) * a + rng.uniform(0, 2 * math.pi))
    return skyline_band(distance, heights, colors, "mountains")


def desert_scene(rng: np.random.Generator) -> Scene:
    """Draw a ``desert`` world from ``rng`` (see the module doc)."""
    horizon, appearance = random_appearance(rng, outdoor=True)
    haze = np.array(horizon)
    half = float(rng.uniform(3.0, 6.0))
    sand = rng.dirichlet(np.ones(3)) @ SANDS
    spots = Spots(rng, half, half)
    beyond = partial(spots.beyond, far=OBJECT_REACH)
    stem = _cactus if rng.random() < 0.5 else _dead_bush
    solids: dict[str, Solids] = {"scrub": [], "rocks": [], "stems": []}
    for kind, make, count in (("scrub", _scrub, rng.integers(1, 6)),
                              ("rocks", _rock, rng.integers(0, 4)),
                              ("stems", stem, rng.integers(0, 4))):
        for _ in range(int(count)):
            solids[kind] += make(rng, spots.inside)
    outside = (("scrub", _scrub), ("rocks", _rock), ("stems", stem))
    for _ in range(int(rng.integers(4, 13))):
        kind, make = outside[int(rng.integers(3))]
        solids[kind] += make(rng, beyond)
    parts = [tinted_ground(rng, sand)]
    if (patches := int(rng.integers(0, 5))):
        parts.append(_gravel(rng, sand, patches, half + 2.0))
    if rng.random() < 0.7:
        parts.append(_dunes(rng, sand))
    if (mesas := int(rng.integers(0, 5))):
        parts.append(_mesas(rng, mesas, haze))
    parts.append(_mountains(rng, haze))
    parts += [_part([m for m, _ in group], [c for _, c in group], kind, True)
              for kind, group in solids.items() if group]
    return Scene(name="desert", bounds=((-half, -half), (half, half)), meshes=tuple(parts),
                 fence=True, ground_plane=False, sky_color=horizon, appearance=appearance)
