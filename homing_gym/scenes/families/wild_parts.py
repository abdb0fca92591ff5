"""Building blocks of the natural world families (:mod:`~homing_gym.scenes.families.forest`,
:mod:`~homing_gym.scenes.families.rocky`): where obstacles may stand on a fenced square
(:class:`Footprints`), a mottled ground disc, a skyline band, trunks and logs (closed
cylinders between two points), angular rocks and thin leaf or grass blades. Units:
metres, z up, the floor at z = 0; colours RGB in [0, 1].
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import trimesh

from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.random_nature import GAP, _disc, _unit_ball

RGB = np.ndarray
Mesh = tuple[np.ndarray, np.ndarray]


def _point_distances(p: np.ndarray, s0: np.ndarray, s1: np.ndarray) -> np.ndarray:
    """Distances (metres) from floor points ``p`` to the floor segments ``s0-s1`` (arrays
    ``(n, 2)`` broadcast against each other)."""
    dx, dy = s1[..., 0] - s0[..., 0], s1[..., 1] - s0[..., 1]
    px, py = p[..., 0] - s0[..., 0], p[..., 1] - s0[..., 1]
    length2 = dx * dx + dy * dy
    t = np.clip((px * dx + py * dy) / np.where(length2 > 0, length2, 1.0), 0.0, 1.0)
    return np.hypot(px - t * dx, py - t * dy)


def _segment_distances(a0: np.ndarray, a1: np.ndarray, b0: np.ndarray, b1: np.ndarray
                       ) -> np.ndarray:
    """Least distances (metres) between the floor segment ``a0-a1`` and each segment
    ``b0[i]-b1[i]`` (``(n, 2)`` arrays): 0 where they cross."""
    def side(o, p, q):
        return (p[..., 0] - o[..., 0]) * (q[..., 1] - o[..., 1]) - (p[..., 1] - o[..., 1]) * (
            q[..., 0] - o[..., 0])

    crossing = ((side(a0, a1, b0) * side(a0, a1, b1) < 0)
                & (side(b0, b1, a0) * side(b0, b1, a1) < 0))
    ends = np.minimum.reduce([_point_distances(a0, b0, b1), _point_distances(a1, b0, b1),
                              _point_distances(b0, a0, a1), _point_distances(b1, a0, a1)])
    return np.where(crossing, 0.0, ends)


class Footprints:
    """Floor footprints of the obstacles placed so far, each a capsule (a segment from
    ``a`` to ``b`` widened by ``reach`` metres; a disc when ``a == b``), and where a new
    one fits: ``gap`` metres from every other one and, inside the fenced square of half
    side ``half``, from the fence too. Obstacles ``gap`` >= 0.4 m apart and off the fence
    leave every part of the floor reachable for the robot's 0.32 m disc."""

    def __init__(self, half: float, gap: float = GAP):
        self.half, self.gap = half, gap
        self.starts, self.ends = np.zeros((0, 2)), np.zeros((0, 2))
        self.reaches = np.zeros(0)

    def fits(self, a, b, reach: float) -> bool:
        """Whether the capsule ``a``-``b`` of ``reach`` keeps ``gap`` from the others."""
        a, b = np.asarray(a, float), np.asarray(b, float)
        need = reach + self.reaches + self.gap
        middle = (self.starts + self.ends) / 2
        spans = np.hypot(*(self.ends - self.starts).T) / 2 + math.dist(a, b) / 2
        near = np.hypot(*(middle - (a + b) / 2).T) - spans < need    # a lower bound
        return bool(np.all(_segment_distances(a, b, self.starts[near], self.ends[near])
                           >= need[near]))

    def add(self, a, b, reach: float) -> None:
        """Note the capsule ``a``-``b`` of ``reach`` (metres) as placed."""
        self.starts = np.vstack([self.starts, a])
        self.ends = np.vstack([self.ends, b])
        self.reaches = np.append(self.reaches, reach)

    def place(self, rng: np.random.Generator, reach: float, length: float = 0.0,
              inside: bool = True, far: float = 12.0, tries: int = 40
              ) -> tuple[np.ndarray, np.ndarray] | None:
        """Ends ``(a, b)`` of a new capsule of ``length`` and ``reach`` (metres) at a
        random place and direction that fits, and note it; ``inside``: wholly on the
        fenced square, ``gap`` from the fence; otherwise beyond the fence, up to ``far``
        metres from the centre. ``None`` after ``tries`` draws that do not fit."""
        for _ in range(tries):
            if inside:
                room = self.half - reach - self.gap - length / 2
                if room <= 0:
                    return None
                centre = rng.uniform(-room, room, 2)
            else:
                r, angle = rng.uniform(self.half + reach, far), rng.uniform(0, 2 * math.pi)
                centre = np.array([r * math.cos(angle), r * math.sin(angle)])
                if np.abs(centre).max() < self.half + reach + length / 2 + 0.3:
                    continue                             # over the fence
            angle = rng.uniform(0, math.pi)
            half_span = length / 2 * np.array([math.cos(angle), math.sin(angle)])
            a, b = centre - half_span, centre + half_span
            if self.fits(a, b, reach):
                self.add(a, b, reach)
                return a, b
        return None


def open_part(triangles: np.ndarray, colors: np.ndarray, name: str) -> MeshPart:
    """A non-colliding part of loose triangles ``(F, 3, 3)`` (blades, fronds, tubes), one
    colour ``(F, 3)`` each; no closed solids."""
    return MeshPart(triangles.reshape(-1, 3), np.arange(3 * len(triangles)).reshape(-1, 3),
                    np.clip(colors, 0, 1), collision=False, name=name, solid_faces=())


def ground(rng: np.random.Generator, dark: RGB, light: RGB) -> MeshPart:
    """The ground out to :data:`~homing_gym.scenes.random_nature.GROUND_RADIUS` metres
    (random_nature's disc), non-colliding, each face a blend of ``dark`` and ``light``:
    patches 1.5-5 m across (a few random waves over the floor) speckled face by face (leaf
    litter, gravel). Plain colours, not a texture: a textured ground halves the ray
    caster's speed."""
    vertices, faces = _disc()
    centres = vertices[faces].mean(axis=1)[:, :2]
    waves = rng.normal(size=(4, 2))
    waves *= (2 * math.pi / rng.uniform(1.5, 5.0, 4) / np.linalg.norm(waves, axis=1))[:, None]
    patches = np.sin(centres @ waves.T + rng.uniform(0, 2 * math.pi, 4)).mean(axis=1)
    t = np.clip(0.5 + 0.7 * patches + rng.uniform(-0.3, 0.3, len(faces)), 0, 1)[:, None]
    colors = dark + t * (np.asarray(light) - dark)
    return MeshPart(vertices, faces, np.clip(colors, 0, 1), collision=False, name="ground",
                    solid_faces=())


def skyline(rng: np.random.Generator, distance: tuple[float, float], base: float,
            relief: float, roughness: float, row_colors: tuple[RGB, RGB], name: str,
            n: int = 120) -> MeshPart:
    """A ring band ``distance`` = (near, far) metres away facing inwards (non-colliding;
    TinyRenderer culls back faces) whose top edge rises from ``base`` metres by up to
    ``relief`` metres: a sum of ``n // 3`` random waves around the ring, the ``k``-th
    ``k ** (roughness - 2)`` as strong (``roughness`` 0: rolling hills, 1: jagged peaks
    and notches). Two rows of quads, the lower in ``row_colors[0]``, the upper in
    ``row_colors[1]``, each face varied by up to 4 %; the foot's distance rises and falls
    smoothly, and the top leans back by a tenth of it (a slope, not a wall)."""
    a = np.linspace(0, 2 * math.pi, n, endpoint=False)

    def waves(count: int, exponent: float) -> np.ndarray:
        """A sum of ``count`` random waves around the ring, scaled to [0, 1]."""
        k = np.arange(1, count + 1)
        sum_ = ((rng.uniform(0.3, 1.0, count) * k ** exponent)[:, None]
                * np.cos(k[:, None] * a + rng.uniform(0, 2 * math.pi, (count, 1)))).sum(axis=0)
        return (sum_ - sum_.min()) / max(np.ptp(sum_), 1e-9)

    heights = base + relief * waves(n // 3, roughness - 2.0)
    dist = distance[0] + (distance[1] - distance[0]) * waves(4, -1.0)
    unit = np.stack([np.cos(a), np.sin(a), np.zeros(n)], axis=1)
    foot = dist[:, None] * unit
    mid = foot * 1.045 + [0, 0, 1] * (0.45 * heights)[:, None]
    top = foot * 1.1 + [0, 0, 1] * heights[:, None]
    vertices = np.concatenate([foot, mid, top])
    faces, colors = [], []
    for row, color in enumerate(row_colors):
        lo, hi = row * n, (row + 1) * n
        for j in range(n):
            j1 = (j + 1) % n
            faces += [[lo + j, hi + j1, lo + j1], [lo + j, hi + j, hi + j1]]
        colors.append(np.broadcast_to(color, (2 * n, 3)))
    colors = np.concatenate(colors) * rng.uniform(0.96, 1.04, (len(faces), 1))
    return MeshPart(vertices, np.array(faces), np.clip(colors, 0, 1), collision=False,
                    name=name, solid_faces=())


@lru_cache(maxsize=4)
def _unit_cylinder(sections: int) -> Mesh:
    """A closed cylinder of radius 1 from z = 0 to z = 1 with ``sections`` sides (trimesh's,
    made once per ``sections``)."""
    cylinder = trimesh.creation.cylinder(radius=1.0, height=1.0, sections=sections)
    vertices, faces = np.array(cylinder.vertices) + [0, 0, 0.5], np.array(cylinder.faces)
    vertices.flags.writeable = faces.flags.writeable = False
    return vertices, faces


def cylinder(start, end, radius: float, top_radius: float, sections: int = 10) -> Mesh:
    """A closed tapered cylinder (wound outwards) from point ``start`` to point ``end``
    (metres), ``radius`` at the start and ``top_radius`` at the end: a trunk, a log."""
    start, end = np.asarray(start, float), np.asarray(end, float)
    unit, faces = _unit_cylinder(sections)
    axis = end - start
    length = float(np.linalg.norm(axis))
    w = axis / length
    u = np.array([w[2], 0.0, -w[0]]) if abs(w[1]) < 0.9 else np.array([0.0, -w[2], w[1]])
    u /= np.linalg.norm(u)                               # u is perpendicular to w
    v = np.array([w[1] * u[2] - w[2] * u[1], w[2] * u[0] - w[0] * u[2],
                  w[0] * u[1] - w[1] * u[0]])            # w x u: u, v, w right-handed
    r = radius + (top_radius - radius) * unit[:, 2:3]
    local = np.column_stack([unit[:, :2] * r, unit[:, 2] * length])
    return start + local @ np.stack([u, v, w]), faces


def tubes(feet: np.ndarray, heights: np.ndarray, radii: np.ndarray, taper: float,
          sections: int = 6) -> np.ndarray:
    """Open upright tubes (no caps: far trunks no one sees from above or below), one per
    floor point of ``feet`` ``(N, 2)``, from 0.1 m under the ground to ``heights``
    metres, ``radii`` at the foot narrowing by ``taper`` (a fraction) to the top: their
    triangles ``(N, 2 * sections, 3, 3)``."""
    a = np.linspace(0, 2 * math.pi, sections + 1)
    ring = np.column_stack([np.cos(a), np.sin(a)])                      # (S + 1, 2)
    n = len(feet)
    low = np.concatenate([feet[:, None] + radii[:, None, None] * ring,
                          np.full((n, sections + 1, 1), -0.1)], axis=2)
    high = np.concatenate([feet[:, None] + (1 - taper) * radii[:, None, None] * ring,
                           np.broadcast_to(heights[:, None, None], (n, sections + 1, 1))], axis=2)
    quads = [low[:, :-1], low[:, 1:], high[:, 1:], high[:, :-1]]
    first = np.stack([quads[0], quads[1], quads[2]], axis=2)
    second = np.stack([quads[0], quads[2], quads[3]], axis=2)
    return np.concatenate([first, second], axis=1)


@lru_cache(maxsize=1)
def unit_icosahedron() -> Mesh:
    """Vertices and faces of trimesh's icosahedron of radius 1 (20 faces, made once): a
    low-poly crown."""
    ball = trimesh.creation.icosahedron()
    vertices, faces = np.array(ball.vertices), np.array(ball.faces)
    vertices.flags.writeable = faces.flags.writeable = False
    return vertices, faces


def rock(rng: np.random.Generator, centre, size, cuts: int, coarse: bool = False,
         tilt: float = 0.0, yaw: float | None = None, sink: float = 0.1) -> Mesh:
    """A closed angular rock ``(vertices, faces)``: an icosphere (80 faces; ``coarse``:
    an icosahedron, 20) pushed in and out by up to 25 %, scaled to the half sizes
    ``size`` (x, y, z, metres), flattened by ``cuts`` random fracture planes that shave
    up to 35 % of its size off a side, tilted by ``tilt`` radians about its x axis,
    turned by ``yaw`` radians about z (``None``: at random) and sunk ``sink`` of its
    height into the ground at floor point ``centre``."""
    ball, faces = unit_icosahedron() if coarse else _unit_ball()
    vertices = ball * rng.uniform(0.75, 1.25, (len(ball), 1))
    for _ in range(cuts):
        normal = rng.normal(size=3)
        normal[2] = abs(normal[2])                       # cuts face up or sideways
        normal /= np.linalg.norm(normal)
        depth = float(rng.uniform(0.65, 0.95))
        over = vertices @ normal - depth
        vertices = vertices - np.maximum(over, 0)[:, None] * normal
    vertices = vertices * np.asarray(size)
    c, s = math.cos(tilt), math.sin(tilt)
    vertices = vertices @ np.array([[1, 0, 0], [0, c, s], [0, -s, c]])
    yaw = rng.uniform(0, 2 * math.pi) if yaw is None else yaw
    c, s = math.cos(yaw), math.sin(yaw)
    vertices = vertices @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
    low = vertices[:, 2].min()
    vertices[:, 2] -= low + sink * (vertices[:, 2].max() - low)
    return vertices + [centre[0], centre[1], 0.0], faces


def reach(vertices: np.ndarray, centre) -> float:
    """Radius (metres) of the floor disc about ``centre`` that holds every vertex."""
    return float(np.hypot(*(vertices[:, :2] - np.asarray(centre)[:2]).T).max())


def blades(rng: np.random.Generator, feet: np.ndarray, height: tuple[float, float],
           width: tuple[float, float], lean: tuple[float, float]) -> np.ndarray:
    """Thin triangles ``(N, 3, 3)``, one per floor point of ``feet`` ``(N, 2)``: a base
    ``width`` metres wide across a random direction, a tip ``height`` metres up leaning
    ``lean`` times its height away in another random direction (fern fronds, grass)."""
    n = len(feet)

    def unit(angle):
        return np.column_stack([np.cos(angle), np.sin(angle)])

    across = rng.uniform(*width, n)[:, None] / 2 * unit(rng.uniform(0, 2 * math.pi, n))
    tall = rng.uniform(*height, n)
    tip = feet + rng.uniform(*lean, n)[:, None] * tall[:, None] * unit(
        rng.uniform(0, 2 * math.pi, n))
    zero = np.zeros((n, 1))
    return np.stack([np.hstack([feet - across, zero]), np.hstack([feet + across, zero]),
                     np.hstack([tip, tall[:, None]])], axis=1)
