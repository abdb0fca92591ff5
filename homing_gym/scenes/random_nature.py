"""``random_nature``: a procedural outdoor world, new every episode (drawn from the
episode's random generator, so ``reset(seed=...)`` reproduces it).

No walls: a fence (invisible, :attr:`Scene.fence`) keeps the robot on a 6-10 m square
of open ground. On it stand trees (a trunk, 0.04-0.15 m radius, and a crown of leaves
from 0.5 m up, out of the robot's way), rocks (lumpy solids 0.1-0.6 m high) and bushes
(low green lumps), each of its own size and colour. The ground reaches 28 m out, its
faces in varied greens and browns; beyond the square, out of reach, stand more trees, and
a ring of hills 18-26 m away gives a horizon that stays put while the robot moves (the
distant features a navigating insect uses). The sky is pale blue with the ray caster
(TinyRenderer's background stays white). Every object is a :class:`MeshPart`: the
robot bumps into trunks, rocks and bushes (their solid cross-section at its height,
:mod:`homing_gym.scenes.footprint`), never into crowns, ground or hills.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import trimesh

from homing_gym.scenes.base import Scene
from homing_gym.scenes.mesh_part import MeshPart

SKY = (0.62, 0.76, 0.92)
#: The ground's and the hills' reach (metres): within TinyRenderer's 30 m far plane
#: (:class:`~homing_gym.render.panorama.CameraConfig`), so both renderers show them.
GROUND_RADIUS = 28.0
HILL_DISTANCE = (18.0, 26.0)
#: Least gap (metres) between the footprints of two obstacles: the robot (0.32 m) fits.
GAP = 0.4


def _part(meshes: list[tuple[np.ndarray, np.ndarray]], colors: list[np.ndarray], name: str,
          collision: bool) -> MeshPart:
    """One part of several closed solids (each mesh, ``(vertices, faces)``, one solid,
    wound outwards), each face in its mesh's colour (``colors``: one RGB per mesh)."""
    counts = [len(faces) for _, faces in meshes]
    offsets = np.cumsum([0] + [len(vertices) for vertices, _ in meshes[:-1]])
    vertices = np.concatenate([v for v, _ in meshes])
    faces = np.concatenate([f + o for (_, f), o in zip(meshes, offsets)])
    face_colors = np.concatenate([np.broadcast_to(c, (n, 3)) for n, c in zip(counts, colors)])
    ends = np.cumsum(counts)
    solids = tuple(np.arange(end - n, end) for n, end in zip(counts, ends))
    return MeshPart(vertices, faces, np.clip(face_colors, 0, 1), collision=collision,
                    name=name, solid_faces=solids)


@lru_cache(maxsize=1)
def _unit_ball() -> tuple[np.ndarray, np.ndarray]:
    """Vertices and faces of trimesh's icosphere of one subdivision and radius 1 (made
    once: every lump and crown starts from it)."""
    ball = trimesh.creation.icosphere(subdivisions=1)
    vertices, faces = np.array(ball.vertices), np.array(ball.faces)
    vertices.flags.writeable = faces.flags.writeable = False
    return vertices, faces


def _lump(rng: np.random.Generator, centre, size) -> tuple[np.ndarray, np.ndarray]:
    """A closed lumpy solid ``(vertices, faces)``: an icosphere scaled to ``size`` (x, y, z
    half sizes), its corners pushed in and out by up to 25 %, standing on the ground at
    ``centre``."""
    ball, faces = _unit_ball()
    vertices = ball * rng.uniform(0.75, 1.25, (len(ball), 1))
    vertices = vertices * np.asarray(size)
    vertices[:, 2] -= vertices[:, 2].min() + 0.05 * size[2]     # sunk a little
    return vertices + [centre[0], centre[1], 0.0], faces


@lru_cache(maxsize=1)
def _unit_trunk() -> tuple[np.ndarray, np.ndarray]:
    """Vertices and faces of trimesh's 10-sided cylinder of radius 1 and height 1 about
    the origin (made once; scaled, it gives the very vertices trimesh makes for another
    radius and height)."""
    trunk = trimesh.creation.cylinder(radius=1.0, height=1.0, sections=10)
    vertices, faces = np.array(trunk.vertices), np.array(trunk.faces)
    vertices.flags.writeable = faces.flags.writeable = False
    return vertices, faces


def _tree(rng: np.random.Generator, xy) -> tuple[list, list]:
    """A trunk and a crown (each ``(vertices, faces)``) at floor point ``xy``, and their
    colours."""
    radius, height = float(rng.uniform(0.04, 0.15)), float(rng.uniform(1.5, 4.0))
    unit, trunk_faces = _unit_trunk()
    trunk = unit * [radius, radius, height] + [xy[0], xy[1], height / 2]
    crown_r = float(rng.uniform(0.4, 1.2))
    ball, faces = _unit_ball()
    crown = ball * [crown_r, crown_r, crown_r * rng.uniform(0.8, 1.6)]
    crown *= rng.uniform(0.85, 1.15, (len(crown), 1))
    low = max(0.5, height - crown_r)
    crown = crown + (xy[0], xy[1], low - crown[:, 2].min())
    bark = np.array([0.35, 0.25, 0.15]) * rng.uniform(0.6, 1.3)
    leaves = np.array([rng.uniform(0.1, 0.35), rng.uniform(0.35, 0.65), rng.uniform(0.05, 0.25)])
    return [(trunk, trunk_faces), (crown, faces)], [bark, leaves]


@lru_cache(maxsize=1)
def _disc() -> tuple[np.ndarray, np.ndarray]:
    """Vertices and faces of a flat disc of :data:`GROUND_RADIUS`: 14 rings growing
    outwards from 0.5 m, 36 sectors (made once)."""
    radii = np.concatenate([[0.0], np.geomspace(0.5, GROUND_RADIUS, 14)])
    sectors = 36
    a = np.linspace(0, 2 * math.pi, sectors, endpoint=False)
    ring = np.stack([np.cos(a), np.sin(a), np.zeros(sectors)], axis=1)
    vertices = np.concatenate([[[0.0, 0.0, 0.0]]] + [r * ring for r in radii[1:]])
    faces = [[0, 1 + k, 1 + (k + 1) % sectors] for k in range(sectors)]
    for i in range(len(radii) - 2):
        inner, outer = 1 + i * sectors, 1 + (i + 1) * sectors
        for k in range(sectors):
            k1 = (k + 1) % sectors
            faces += [[inner + k, outer + k, outer + k1], [inner + k, outer + k1, inner + k1]]
    faces = np.array(faces)
    vertices.flags.writeable = faces.flags.writeable = False
    return vertices, faces


def _ground(rng: np.random.Generator) -> MeshPart:
    """A disc of :data:`GROUND_RADIUS` (:func:`_disc`), faces in varied greens and
    browns."""
    vertices, faces = _disc()
    base = np.array([rng.uniform(0.25, 0.45), rng.uniform(0.4, 0.6), rng.uniform(0.15, 0.3)])
    colors = base * rng.uniform(0.75, 1.25, (len(faces), 1)) + rng.uniform(-0.05, 0.05,
                                                                           (len(faces), 3))
    return MeshPart(vertices, faces, np.clip(colors, 0, 1), collision=False,
                    name="ground", solid_faces=())           # an open surface


def _hills(rng: np.random.Generator) -> MeshPart:
    """A ring of hills: a band of quads facing inwards (TinyRenderer culls back faces)
    whose top edge rises and falls smoothly."""
    n = 72
    a = np.linspace(0, 2 * math.pi, n, endpoint=False)
    heights = np.zeros(n)
    for k in range(1, 6):      # a few random harmonics: a smooth, irregular skyline
        heights += rng.uniform(0.5, 3.0) / k * np.cos(k * a + rng.uniform(0, 2 * math.pi))
    heights = 1.5 + heights - heights.min() + rng.uniform(0, 1.5)
    distance = rng.uniform(*HILL_DISTANCE, n)
    foot = np.stack([distance * np.cos(a), distance * np.sin(a), np.zeros(n)], axis=1)
    top = foot * 1.02 + np.stack([np.zeros(n), np.zeros(n), heights], axis=1)
    vertices = np.concatenate([foot, top])
    faces = []
    for k in range(n):
        k1 = (k + 1) % n
        faces += [[k, n + k1, k1], [k, n + k, n + k1]]      # facing the middle
    tint = np.array([rng.uniform(0.3, 0.45), rng.uniform(0.4, 0.55), rng.uniform(0.45, 0.6)])
    colors = tint * rng.uniform(0.85, 1.15, (len(faces), 1))
    return MeshPart(vertices, np.array(faces), np.clip(colors, 0, 1), collision=False,
                    name="hills", solid_faces=())            # an open band


def random_nature_scene(rng: np.random.Generator) -> Scene:
    """Draw a ``random_nature`` world from ``rng`` (see the module doc)."""
    half = float(rng.uniform(3.0, 5.0))
    placed: list[tuple[float, float, float]] = []       # x, y, footprint radius

    def spot(reach: float, inside: bool) -> tuple[float, float] | None:
        for _ in range(50):
            if inside:
                xy = rng.uniform(-half + reach, half - reach, 2)
            else:                                   # a ring beyond the fence
                r, a = rng.uniform(half + 1.0, half + 12.0), rng.uniform(0, 2 * math.pi)
                xy = np.array([r * math.cos(a), r * math.sin(a)])
            if all(math.dist(xy, p[:2]) >= reach + p[2] + GAP for p in placed):
                placed.append((float(xy[0]), float(xy[1]), reach))
                return float(xy[0]), float(xy[1])
        return None

    trunks, trunk_colors, crowns, crown_colors = [], [], [], []
    for inside, count in ((True, int(rng.integers(2, 8))), (False, int(rng.integers(6, 20)))):
        for _ in range(count):
            if (xy := spot(0.15, inside)) is not None:
                (trunk, crown), (bark, leaves) = _tree(rng, xy)
                trunks.append(trunk), trunk_colors.append(bark)
                crowns.append(crown), crown_colors.append(leaves)
    lumps, lump_colors = [], []
    for _ in range(int(rng.integers(3, 12))):
        bush = rng.random() < 0.4
        size = (rng.uniform(0.15, 0.4, 2) if bush else rng.uniform(0.08, 0.35, 2))
        height = rng.uniform(0.2, 0.5) if bush else rng.uniform(0.1, 0.6)
        if (xy := spot(float(size.max()) * 1.25, True)) is not None:
            lumps.append(_lump(rng, xy, (*size, height)))
            lump_colors.append(np.array([rng.uniform(0.1, 0.3), rng.uniform(0.35, 0.6),
                                         rng.uniform(0.05, 0.2)]) if bush
                               else np.full(3, rng.uniform(0.35, 0.7)) * rng.uniform(0.9, 1.1, 3))
    parts = [_ground(rng), _hills(rng), _part(trunks, trunk_colors, "trunks", True),
             _part(crowns, crown_colors, "crowns", False)]
    if lumps:
        parts.append(_part(lumps, lump_colors, "rocks_and_bushes", True))
    return Scene(name="random_nature", bounds=((-half, -half), (half, half)),
                 meshes=tuple(parts), fence=True, ground_plane=False, sky_color=SKY)
