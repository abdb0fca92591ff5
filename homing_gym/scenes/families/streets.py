"""``streets``: a built outdoor world, a street or a plaza between building blocks, new
every episode (drawn from the episode's random generator).

Half the worlds are a long street: a fenced free floor (:attr:`Scene.fence`) 6-12 m
across and 14-20 m along, between two rows of building blocks whose facades stand on
its long sides; most streets have an asphalt road with a kerb, lane markings, sometimes
a zebra crossing and parked cars, and pavements on both sides, the others are paved
all over for pedestrians. The other half are a plaza, 8-12 m a side, fronted by blocks
on all four sides, with a fountain, a monument or a large tree in the middle. Blocks
are boxes 6-23 m high (two to six storeys), 4-14 m wide and up to 14 m deep, their
facades rows of windows (a texture made per world: tinted wall, glass of varied
darkness, frames, some lit windows, shop fronts on the ground floor); gaps between
them are side streets, through which up to 19 farther blocks (9-30 m high, up to
27.5 m away: a skyline that stays put as the robot moves) show. Street furniture stands
on the free floor: lamp posts (3.5-6 m), benches, bins, bollards, trees in planters
(crowns from 1.8 m up) and, on roads, parked cars. The ground (paving, 28 m round) and
its strips (road, kerbs, markings) are flat and never block.

The robot bumps into the facades, the furniture and the cars (every footprint at
least :data:`GAP` from the next and either touching the edge of the free floor or
:data:`GAP` clear of it, so everything can be driven round), never into crowns,
water, ground or markings. Randomised: the layout and sizes, every colour, the
facade textures and the paving (tinted shipped textures), the counts of everything,
and the sky and light (:func:`~homing_gym.scenes.appearance.random_appearance`).
``scene.metadata["layout"]`` is ``"street"`` or ``"plaza"``.
"""

from __future__ import annotations

import math

import numpy as np

from homing_gym.scenes.appearance import random_appearance
from homing_gym.scenes.base import Scene
from homing_gym.scenes.families.built_parts import (box_mesh, floor_quad, prism_mesh,
                                                    quads_part, scaled, solids_part,
                                                    texture_color, tinted)
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.random_nature import GROUND_RADIUS, _lump, _unit_ball

#: Least gap (metres) between two footprints on the free floor, and between a footprint
#: and the edge unless it touches it: LocalHoming's 0.22 m disc passes with room.
GAP = 0.55
#: Farthest any building corner lies from the middle (metres): within the ground.
REACH = 27.5
#: Wall colours of facades (RGB, 0-1): plaster, stone, brick, concrete, painted.
FACADE_COLORS = ((0.88, 0.83, 0.72), (0.93, 0.91, 0.86), (0.72, 0.42, 0.33),
                 (0.62, 0.62, 0.64), (0.82, 0.66, 0.45), (0.56, 0.62, 0.72),
                 (0.5, 0.45, 0.42), (0.78, 0.8, 0.7))
#: Paving textures (shipped name, metres per repeat, contrast).
PAVING = (("floor_tiles", (1.5, 3.5), 1.5), ("concrete", (3.0, 6.0), 1.0),
          ("bricks_red", (1.0, 1.6), 0.6), ("bricks_grey", (1.0, 1.6), 0.6),
          ("checker_dark", (2.0, 4.0), 0.35))
#: Colours (RGB) of paintwork: cars, bins, lamp posts pick from it.
PAINT = ((0.9, 0.9, 0.88), (0.75, 0.76, 0.78), (0.12, 0.12, 0.13), (0.65, 0.12, 0.1),
         (0.15, 0.25, 0.55), (0.12, 0.3, 0.18), (0.85, 0.7, 0.15), (0.4, 0.42, 0.45))

Rect = tuple[float, float, float, float]


def _choice(rng: np.random.Generator, options):
    return options[int(rng.integers(len(options)))]


def _varied(rng: np.random.Generator, rgb, spread: float = 0.12) -> np.ndarray:
    """``rgb`` with its brightness and each channel varied by up to ``spread``."""
    return np.clip(np.asarray(rgb) * rng.uniform(1 - spread, 1 + spread)
                   + rng.uniform(-spread / 3, spread / 3, 3), 0, 1)


class _FacadeStyle:
    """A facade texture (uint8, 256 x 128: eight storeys of four window bays) and its
    size in metres (``tile``: four bays across, eight storeys up)."""

    def __init__(self, rng: np.random.Generator, shop_front: bool):
        self.bay = float(rng.uniform(1.6, 3.2))
        self.storey = float(rng.uniform(2.9, 3.6))
        self.tile = (4 * self.bay, 8 * self.storey)
        wall_rgb = _varied(rng, _choice(rng, FACADE_COLORS))
        name, metres, contrast = _choice(rng, (("concrete", 2.0, 0.5), ("concrete", 2.0, 1.0),
                                               ("bricks_grey", 1.0, 0.5),
                                               ("bricks_red", 1.0, 0.4)))
        if name == "bricks_red":                       # the bricks' own colour, lighter or darker
            wall_rgb = np.full(3, rng.uniform(0.75, 1.1))
        source = tinted(name, wall_rgb, contrast)
        image = scaled(source, (self.tile[0] / metres, self.tile[1] / metres), (256, 128))
        image = image.astype(np.float64)
        glass = np.array([0.12, 0.15, 0.2]) * rng.uniform(0.6, 2.0)
        frame = np.full(3, rng.uniform(0.85, 0.98)) if rng.random() < 0.6 else wall_rgb * 0.5
        modern = rng.random() < 0.2
        width = rng.uniform(0.75, 0.9) if modern else rng.uniform(0.35, 0.65)
        height = rng.uniform(0.6, 0.68) if modern else rng.uniform(0.4, 0.62)
        sill = 0.2                                     # of a storey, as the sizes
        if rng.random() < 0.5:                         # a band between storeys
            band = wall_rgb * rng.uniform(0.6, 1.2)
            for k in range(8):
                image[32 * k + 30:32 * k + 32] = 255 * np.clip(band, 0, 1)
        for k in range(8):                             # storey k from the bottom
            bottom = 256 - 32 * k
            shop = shop_front and k == 0
            w, h, s = (0.85, 0.72, 0.04) if shop else (width, height, sill)
            for j in range(4):
                x0, x1 = int(32 * j + 16 - 16 * w), int(32 * j + 16 + 16 * w)
                y0, y1 = int(bottom - 32 * (s + h)), int(bottom - 32 * s)
                image[y0 - 1:y1 + 1, x0 - 1:x1 + 1] = 255 * np.clip(frame, 0, 1)
                pane = glass * rng.uniform(0.7, 1.5)
                if rng.random() < 0.08:                # a lit window
                    pane = np.array([0.95, 0.85, 0.55]) * rng.uniform(0.7, 1.0)
                shade = np.linspace(1.3, 0.8, y1 - y0)[:, None, None]    # sky reflected
                image[y0:y1, x0:x1] = 255 * np.clip(pane * shade, 0, 1)
                if not shop and rng.random() < 0.2:    # blinds half down
                    image[y0:(y0 + y1) // 2, x0:x1] = 255 * np.clip(
                        np.full(3, rng.uniform(0.6, 0.9)), 0, 1)
                if shop:                               # a sign board over the shop
                    image[y0 - 5:y0 - 1, x0:x1] = 255 * _varied(rng, _choice(rng, PAINT), 0.3)
        self.texture = np.clip(image, 0, 255).astype(np.uint8)


class _Floor:
    """Footprints (axis-aligned rectangles, metres) taken on the free floor ``|x| <= hx``,
    ``|y| <= hy``: each at least :data:`GAP` from every other and, on each side, either
    touching the edge or :data:`GAP` clear of it."""

    def __init__(self, hx: float, hy: float):
        self.hx, self.hy = hx, hy
        self.rects: list[Rect] = []

    def take(self, rect: Rect) -> bool:
        """Take ``rect`` = (x0, y0, x1, y1) if it fits (then ``True``)."""
        x0, y0, x1, y1 = rect
        for gap in (x0 + self.hx, self.hx - x1, y0 + self.hy, self.hy - y1):
            if gap < -1e-9 or 1e-6 < gap < GAP:
                return False
        for a0, b0, a1, b1 in self.rects:
            dx, dy = max(a0 - x1, x0 - a1, 0.0), max(b0 - y1, y0 - b1, 0.0)
            if math.hypot(dx, dy) < GAP:
                return False
        self.rects.append(rect)
        return True


class _Kit:
    """The meshes of one world, gathered by part: colliding furniture, tree crowns,
    water, and flat ground marks (quads)."""

    def __init__(self, rng: np.random.Generator, floor: _Floor):
        self.rng, self.floor = rng, floor
        self.solids: list = []
        self.solid_colors: list = []
        self.crowns: list = []
        self.crown_colors: list = []
        self.water: list = []
        self.water_colors: list = []
        self.marks: list = []
        self.mark_colors: list = []

    def solid(self, mesh, color) -> None:
        self.solids.append(mesh[:2])
        self.solid_colors.append(np.clip(color, 0, 1))

    def mark(self, x0: float, y0: float, x1: float, y1: float, z: float, color) -> None:
        self.marks.append(floor_quad(x0, y0, x1, y1, z))
        self.mark_colors.append(np.clip(color, 0, 1))

    # the furniture: each returns whether it found room (its footprint was free)

    def lamp_post(self, x: float, y: float, towards: tuple[float, float], style) -> bool:
        """A pole (radius 0.05-0.09 m, 3.5-6 m) on a base, with a lantern on top or an arm
        reaching ``towards`` (a unit vector) with a lamp at its end; ``style`` = (pole
        RGB, height, kind)."""
        color, height, kind = style
        base_r = 0.14
        towards = (float(np.sign(towards[0])), 0.0) if abs(towards[0]) >= abs(towards[1]) \
            else (0.0, float(np.sign(towards[1])))
        if not self.floor.take((x - base_r, y - base_r, x + base_r, y + base_r)):
            return False
        self.solid(prism_mesh((x, y), base_r, 0.0, 0.6, 8), color)
        self.solid(prism_mesh((x, y), 0.07, 0.0, height, 8), color)
        light = np.array([0.98, 0.92, 0.7])
        if kind == "lantern":
            self.solid(box_mesh((x - 0.17, y - 0.17, height), (x + 0.17, y + 0.17, height + 0.45)),
                       light)
            self.solid(box_mesh((x - 0.22, y - 0.22, height + 0.45),
                                (x + 0.22, y + 0.22, height + 0.52)), color)
        else:
            reach = 1.0
            ex, ey = x + reach * towards[0], y + reach * towards[1]
            self.solid(box_mesh((min(x, ex) - 0.04, min(y, ey) - 0.04, height - 0.1),
                                (max(x, ex) + 0.04, max(y, ey) + 0.04, height)), color)
            self.solid(box_mesh((ex - 0.25, ey - 0.25, height - 0.22), (ex + 0.25, ey + 0.25,
                                                                        height - 0.1)), light)
        return True

    def bin(self, x: float, y: float) -> bool:
        """A litter bin: a prism 0.2-0.3 m in radius and 0.7-1 m high with a lid."""
        r, h = float(self.rng.uniform(0.2, 0.3)), float(self.rng.uniform(0.7, 1.0))
        if not self.floor.take((x - r - 0.02, y - r - 0.02, x + r + 0.02, y + r + 0.02)):
            return False
        color = _varied(self.rng, _choice(self.rng, PAINT))
        self.solid(prism_mesh((x, y), r, 0.0, h, 10), color)
        self.solid(prism_mesh((x, y), r + 0.02, h, h + 0.06, 10), color * 0.6)
        return True

    def bollard(self, x: float, y: float, style) -> bool:
        """A bollard; ``style`` = (radius, height, RGB)."""
        r, h, color = style
        if not self.floor.take((x - r, y - r, x + r, y + r)):
            return False
        self.solid(prism_mesh((x, y), r, 0.0, h, 8), color)
        self.solid(prism_mesh((x, y), r * 1.05, h - 0.12, h - 0.06, 8), np.full(3, 0.92))
        return True

    def bench(self, x: float, y: float, facing: tuple[int, int]) -> bool:
        """A bench whose back edge is centred on ``(x, y)`` and whose sitter faces
        ``facing`` (an axis unit vector): a solid seat 0.42-0.48 m high and a backrest to
        0.85 m along its back edge."""
        rng = self.rng
        length, depth = float(rng.uniform(1.2, 2.0)), float(rng.uniform(0.45, 0.6))
        fx, fy = facing
        x, y = x + fx * depth / 2, y + fy * depth / 2
        hx, hy = (depth / 2, length / 2) if fx else (length / 2, depth / 2)
        if not self.floor.take((x - hx, y - hy, x + hx, y + hy)):
            return False
        seat = float(rng.uniform(0.42, 0.48))
        color = (_varied(rng, (0.55, 0.38, 0.22)) if rng.random() < 0.6
                 else _varied(rng, _choice(rng, ((0.65, 0.65, 0.62), (0.15, 0.3, 0.2)))))
        self.solid(box_mesh((x - hx, y - hy, 0.0), (x + hx, y + hy, seat)), color)
        # the backrest along the back edge (opposite ``facing``)
        bx0 = x - hx if fx > 0 else (x + hx - 0.07 if fx < 0 else x - hx)
        by0 = y - hy if fy > 0 else (y + hy - 0.07 if fy < 0 else y - hy)
        bx1 = bx0 + 0.07 if fx else x + hx
        by1 = by0 + 0.07 if fy else y + hy
        self.solid(box_mesh((bx0, by0, seat), (bx1, by1, 0.85)), color * 0.85)
        return True

    def tree(self, x: float, y: float, planter: float) -> bool:
        """A tree (trunk 0.06-0.14 m in radius, a crown from 1.8 m up) in a square
        planter of side ``planter`` metres, 0.4-0.7 m high, filled with soil."""
        rng = self.rng
        half = planter / 2
        if not self.floor.take((x - half, y - half, x + half, y + half)):
            return False
        pot = _varied(rng, _choice(rng, ((0.6, 0.6, 0.58), (0.62, 0.35, 0.22),
                                         (0.3, 0.3, 0.32), (0.5, 0.38, 0.25))))
        top = float(rng.uniform(0.4, 0.7))
        self.solid(box_mesh((x - half, y - half, 0.0), (x + half, y + half, top)), pot)
        self.solid(box_mesh((x - half + 0.06, y - half + 0.06, top),
                            (x + half - 0.06, y + half - 0.06, top + 0.01)),
                   _varied(rng, (0.25, 0.18, 0.1)))
        radius, height = float(rng.uniform(0.06, 0.14)), float(rng.uniform(3.0, 6.0))
        self.solid(prism_mesh((x, y), radius, 0.0, height, 8), _varied(rng, (0.33, 0.25, 0.17)))
        crown_r = float(rng.uniform(0.8, 1.6))
        ball, faces = _unit_ball()
        crown = ball * [crown_r, crown_r, crown_r * rng.uniform(0.8, 1.4)]
        crown = crown * rng.uniform(0.85, 1.15, (len(crown), 1))
        low = max(1.8, height - 1.5 * crown_r)
        self.crowns.append((crown + (x, y, low - crown[:, 2].min()), faces))
        autumn = rng.random() < 0.15
        self.crown_colors.append(np.array([rng.uniform(0.6, 0.85), rng.uniform(0.4, 0.6), 0.1])
                                 if autumn else np.array([rng.uniform(0.1, 0.3),
                                                          rng.uniform(0.35, 0.6),
                                                          rng.uniform(0.05, 0.2)]))
        return True

    def car(self, x: float, y: float) -> bool:
        """A parked car along y: a body 3.8-4.6 x 1.7-1.9 m to 0.75-0.85 m on a dark
        underbody, a cabin of dark glass to 1.3-1.5 m."""
        rng = self.rng
        length, width = float(rng.uniform(3.8, 4.6)), float(rng.uniform(1.7, 1.9))
        hx, hy = width / 2, length / 2
        if not self.floor.take((x - hx, y - hy, x + hx, y + hy)):
            return False
        body = float(rng.uniform(0.75, 0.85))
        self.solid(box_mesh((x - hx + 0.08, y - hy + 0.25, 0.0), (x + hx - 0.08, y + hy - 0.25,
                                                                  0.22)), np.full(3, 0.06))
        self.solid(box_mesh((x - hx, y - hy, 0.22), (x + hx, y + hy, body)),
                   _varied(rng, _choice(rng, PAINT), 0.08))
        cabin = float(rng.uniform(0.45, 0.6)) * length
        shift = float(rng.uniform(-0.1, 0.05)) * length
        self.solid(box_mesh((x - hx + 0.08, y - cabin / 2 + shift, body),
                            (x + hx - 0.08, y + cabin / 2 + shift, float(rng.uniform(1.3, 1.5)))),
                   np.array([0.14, 0.17, 0.22]) * rng.uniform(0.8, 1.6))
        return True

    def fountain(self, x: float, y: float, radius: float) -> bool:
        """A round stone basin of ``radius`` (0.35-0.6 m high) holding water, a column in
        its middle, sometimes with a bowl on top."""
        rng = self.rng
        if not self.floor.take((x - radius, y - radius, x + radius, y + radius)):
            return False
        stone = _varied(rng, (0.72, 0.7, 0.66))
        rim = float(rng.uniform(0.35, 0.6))
        self.solid(prism_mesh((x, y), radius, 0.0, rim, 24), stone)
        self.water.append(prism_mesh((x, y), radius - 0.15, rim - 0.05, rim + 0.005, 24))
        self.water_colors.append(_varied(rng, (0.3, 0.5, 0.68)))
        top = float(rng.uniform(0.9, 2.0))
        self.solid(prism_mesh((x, y), float(rng.uniform(0.12, 0.25)), 0.0, top, 10), stone)
        if rng.random() < 0.5:
            self.solid(prism_mesh((x, y), float(rng.uniform(0.45, 0.7)), top, top + 0.18, 16),
                       stone)
        return True

    def monument(self, x: float, y: float, half: float) -> bool:
        """A plinth ``2 * half`` metres square, 0.8-1.6 m high, under a statue (a lumpy
        bronze or stone figure) or an obelisk."""
        rng = self.rng
        if not self.floor.take((x - half, y - half, x + half, y + half)):
            return False
        stone = _varied(rng, (0.7, 0.68, 0.64))
        plinth = float(rng.uniform(0.8, 1.6))
        self.solid(box_mesh((x - half, y - half, 0.0), (x + half, y + half, plinth)), stone)
        if rng.random() < 0.6:
            vertices, faces = _lump(rng, (x, y), (half * 0.5, half * 0.5, rng.uniform(0.8, 1.4)))
            self.solid((vertices + [0.0, 0.0, plinth], faces),
                       _varied(rng, _choice(rng, ((0.25, 0.38, 0.3), (0.2, 0.17, 0.14),
                                                  (0.8, 0.78, 0.72)))))
        else:
            w = half * 0.35
            self.solid(box_mesh((x - w, y - w, plinth), (x + w, y + w,
                                                         plinth + rng.uniform(2.5, 5.0))), stone)
        return True


def _frontage(rng: np.random.Generator, line: float, axis: int, sign: int, s0: float,
              s1: float, max_gaps: int, floor: tuple[float, float]) -> tuple[list[Rect],
                                                                              list[Rect]]:
    """Building blocks along a facade line (``x = line`` when ``axis`` is 0, else
    ``y = line``) from ``s0`` to ``s1`` along it, reaching away from the free floor on the
    ``sign`` side; up to ``max_gaps`` side streets between them, one at most opening
    onto the free floor (from ``floor[0]`` to ``floor[1]`` along the line). Returns the
    blocks' and the side streets' footprints (x0, y0, x1, y1)."""
    blocks, gaps = [], []
    s = s0
    onto_floor = 0

    def footprint(a: float, b: float, depth: float) -> Rect:
        across = sorted((line, line + sign * depth))
        return ((across[0], a, across[1], b) if axis == 0 else (a, across[0], b, across[1]))

    while s < s1 - 1.0:
        if len(gaps) < max_gaps and s > s0 + 1.0 and s1 - s > 5.0 and rng.random() < 0.3:
            width = min(float(rng.uniform(3.0, 6.0)), s1 - s)
            if s < floor[1] and s + width > floor[0]:
                if onto_floor:
                    continue
                onto_floor += 1
            far = max(abs(s), abs(s + width))
            gaps.append(footprint(s, s + width, math.sqrt(REACH ** 2 - far ** 2) - abs(line)))
            s += width
            continue
        width = min(float(rng.uniform(4.0, 14.0)), s1 - s)
        far = max(abs(s), abs(s + width))
        depth = min(float(rng.uniform(7.0, 14.0)), math.sqrt(max(REACH ** 2 - far ** 2, 0.0))
                    - abs(line))
        if depth >= 3.0:
            blocks.append(footprint(s, s + width, depth))
        s += width
    return blocks, gaps


def _overlap(a: Rect, b: Rect, margin: float = 0.0) -> bool:
    return (a[0] < b[2] + margin and b[0] < a[2] + margin and a[1] < b[3] + margin
            and b[1] < a[3] + margin)


def _far_blocks(rng: np.random.Generator, near: list[Rect], open_area: Rect) -> list[Rect]:
    """Up to 19 blocks 5-12 m a side, 15-24 m from the middle, 1 m clear of ``near``
    and clear of ``open_area``: the skyline seen between and over the near blocks."""
    blocks: list[Rect] = []
    for _ in range(int(rng.integers(10, 20))):
        for _ in range(10):
            w, d = rng.uniform(5.0, 12.0, 2)
            a, r = rng.uniform(-math.pi, math.pi), rng.uniform(15.0, 24.0)
            cx, cy = r * math.cos(a), r * math.sin(a)
            rect = (cx - w / 2, cy - d / 2, cx + w / 2, cy + d / 2)
            if (max(math.hypot(x, y) for x in rect[::2] for y in rect[1::2]) <= REACH
                    and not _overlap(rect, open_area)
                    and not any(_overlap(rect, b, 1.0) for b in near + blocks)):
                blocks.append(rect)
                break
    return blocks


def _ground(texture: np.ndarray, tile: float) -> MeshPart:
    """The paving: a 24-sided disc of :data:`GROUND_RADIUS` (a fan of triangles),
    textured ``tile`` metres per repeat; an open surface."""
    a = np.linspace(0, 2 * math.pi, 24, endpoint=False)
    vertices = np.concatenate([[[0.0, 0.0, 0.0]], GROUND_RADIUS * np.stack(
        [np.cos(a), np.sin(a), np.zeros(24)], 1)])
    k = np.arange(24)
    faces = np.stack([np.zeros(24, int), 1 + k, 1 + (k + 1) % 24], 1)
    return MeshPart(vertices, faces, np.broadcast_to(texture_color(texture), (24, 3)),
                    uvs=vertices[:, :2] / tile, texture=texture, collision=False, name="ground",
                    solid_faces=())


def _paving(rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """A paving texture (tinted shipped texture) and its metres per repeat."""
    name, tiles, contrast = _choice(rng, PAVING)
    grey = rng.uniform(0.75, 1.1) * np.array([1.0, rng.uniform(0.95, 1.02), rng.uniform(0.88, 1.0)])
    return tinted(name, grey, contrast), float(rng.uniform(*tiles))


def _street(rng: np.random.Generator, kit: _Kit, hx: float, hy: float,
            roads: list[np.ndarray]) -> None:
    """The furniture, road and marks of a street along y (see the module doc)."""
    floor = kit.floor
    post = (_varied(rng, _choice(rng, PAINT[1:3] + PAINT[5:6] + PAINT[7:])),
            float(rng.uniform(3.5, 6.0)), _choice(rng, ("lantern", "arm")))
    if rng.random() < 0.7:                                  # a road with pavements
        pavement = float(rng.uniform(1.4, max(1.4, min(2.8, hx - 1.5))))
        road = hx - pavement
        roads.append(floor_quad(-road, -26.0, road, 26.0, 0.002))
        kerb = np.full(3, rng.uniform(0.6, 0.85))
        paint = _choice(rng, (np.array([0.92, 0.92, 0.9]), np.array([0.9, 0.75, 0.2])))
        for side in (-1, 1):
            kit.mark(*sorted((side * road, side * (road + 0.2))), -26.0, 26.0, 0.004, kerb)
            if rng.random() < 0.5:                          # an edge line
                x = side * (road - 0.3)
                kit.mark(x - 0.05, -26.0, x + 0.05, 26.0, 0.005, paint)
        if road >= 2.4:                                     # a dashed centre line
            dash, period = float(rng.uniform(1.0, 3.0)), float(rng.uniform(3.0, 6.0))
            for y in np.arange(-26.0, 26.0 - dash, period):
                kit.mark(-0.06, float(y), 0.06, float(y) + dash, 0.005, paint)
        if rng.random() < 0.5:                              # a zebra crossing
            yz = float(rng.uniform(-hy + 2.0, hy - 4.5))
            for x in np.arange(-road + 0.3, road - 0.5, 1.0):
                kit.mark(float(x), yz, float(x) + 0.5, yz + 2.5, 0.005, np.full(3, 0.93))
        spacing, phase = float(rng.uniform(5.0, 8.0)), float(rng.uniform(0, 3))
        for side in (-1, 1):
            x = side * (road + 0.45)
            for y in np.arange(-hy + 0.8 + phase, hy - 0.5, spacing):
                if kit.lamp_post(x, float(y), (-side, 0.0), post) and rng.random() < 0.4:
                    kit.bin(x, float(y) + 1.3)
            if pavement >= 1.9:
                for y in np.arange(-hy + 0.8 + phase + spacing / 2, hy - 1.0, spacing):
                    size = float(rng.uniform(0.7, min(1.2, pavement - 0.8)))
                    kit.tree(side * (road + 0.25 + size / 2), float(y), size)
            if rng.random() < 0.4:
                b = (float(rng.uniform(0.06, 0.12)), float(rng.uniform(0.5, 1.0)),
                     _varied(rng, _choice(rng, PAINT[1:3] + PAINT[7:])))
                start = float(rng.uniform(-hy + 0.6, hy - 4.0))
                for k in range(int(rng.integers(3, 8))):
                    kit.bollard(side * (road + 0.3), start + 1.3 * k, b)
            if road >= 2.5 and rng.random() < 0.6:
                for _ in range(int(rng.integers(1, 4))):
                    kit.car(side * (road - 0.3 - 0.95), float(rng.uniform(-hy + 2.5, hy - 2.5)))
            for _ in range(int(rng.integers(0, 3))):           # against the facade
                kit.bench(side * hx, float(rng.uniform(-hy + 1.2, hy - 1.2)), (-side, 0))
    else:                                                   # paved for pedestrians
        rows = (0.0,) if hx < 4.5 else (-hx / 2.5, hx / 2.5)
        spacing = float(rng.uniform(3.5, 6.0))
        for x in rows:
            for y in np.arange(-hy + 1.5 + rng.uniform(0, 2), hy - 1.0, spacing):
                pick = rng.random()
                if pick < 0.45:
                    kit.tree(x, float(y), float(rng.uniform(0.8, 1.4)))
                elif pick < 0.75:
                    facing = int(_choice(rng, (-1, 1)))
                    kit.bench(x - facing * 0.25, float(y), (facing, 0))
                else:
                    kit.bin(x, float(y))
        for side in (-1, 1):
            for y in np.arange(-hy + 1.0 + rng.uniform(0, 3), hy - 0.5, rng.uniform(5, 8)):
                kit.lamp_post(side * (hx - 1.0), float(y), (-side, 0.0), post)
        b = (float(rng.uniform(0.06, 0.12)), float(rng.uniform(0.5, 1.0)),
             _varied(rng, _choice(rng, PAINT[1:3] + PAINT[7:])))
        for end in (-1, 1):
            if rng.random() < 0.6:
                for x in np.arange(-hx + 0.8, hx - 0.6, 1.4):
                    kit.bollard(float(x), end * (hy - 0.8), b)


def _plaza(rng: np.random.Generator, kit: _Kit, hx: float, hy: float,
           entrances: list[tuple[int, int, float, float]]) -> None:
    """The furniture of a plaza (see the module doc); ``entrances``: the side streets
    leaving it, as (axis of the side's line, its sign, start, end along it)."""
    cx, cy = rng.uniform(-0.5, 0.5, 2)
    room = min(hx, hy) - 2.2
    pick = rng.random()
    if pick < 0.45:
        radius = float(rng.uniform(1.0, min(2.0, room)))
        kit.fountain(cx, cy, radius)
    elif pick < 0.8:
        radius = float(rng.uniform(0.5, 1.0))
        kit.monument(cx, cy, radius)
    else:
        radius = float(rng.uniform(0.6, 1.1))
        kit.tree(cx, cy, 2 * radius)
    for fx, fy in ((1, 0), (-1, 0), (0, 1), (0, -1)):        # benches facing the middle
        if rng.random() < 0.7:
            d = radius + float(rng.uniform(1.7, 2.5))
            kit.bench(cx - fx * d, cy - fy * d, (fx, fy))
    post = (_varied(rng, _choice(rng, PAINT[1:3] + PAINT[5:6] + PAINT[7:])),
            float(rng.uniform(3.5, 6.0)), _choice(rng, ("lantern", "arm")))
    d = radius + float(rng.uniform(2.0, 3.0))
    for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
        if rng.random() < 0.7:
            x, y = cx + sx * d / math.sqrt(2), cy + sy * d / math.sqrt(2)
            kit.lamp_post(x, y, (-sx / math.sqrt(2), -sy / math.sqrt(2)), post)
    for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):      # trees near the corners
        if rng.random() < 0.6:
            size = float(rng.uniform(0.8, 1.3))
            inset = float(rng.uniform(0.7, 1.4)) + size / 2
            kit.tree(sx * (hx - inset), sy * (hy - inset), size)
    b = (float(rng.uniform(0.06, 0.12)), float(rng.uniform(0.5, 1.0)),
         _varied(rng, _choice(rng, PAINT[1:3] + PAINT[7:])))
    for axis, sign, s0, s1 in entrances:                     # bollards across entrances
        if rng.random() < 0.7:
            inset = float(rng.uniform(0.8, 1.2))
            for s in np.arange(s0 + 0.5, s1 - 0.3, 1.3):
                line = sign * ((hx if axis == 0 else hy) - inset)
                kit.bollard(*((line, float(s)) if axis == 0 else (float(s), line)), b)
    for _ in range(int(rng.integers(1, 4))):
        kit.bin(float(rng.uniform(-hx + 0.9, hx - 0.9)), float(rng.uniform(-hy + 0.9, hy - 0.9)))
    for _ in range(int(rng.integers(0, 3))):                 # benches against the facades
        side = int(_choice(rng, (-1, 1)))
        if rng.random() < 0.5:
            kit.bench(side * hx, float(rng.uniform(-hy + 1.5, hy - 1.5)), (-side, 0))
        else:
            kit.bench(float(rng.uniform(-hx + 1.5, hx - 1.5)), side * hy, (0, -side))


def streets_scene(rng: np.random.Generator) -> Scene:
    """Draw a ``streets`` world from ``rng`` (see the module doc)."""
    horizon, appearance = random_appearance(rng, outdoor=True)
    plaza = bool(rng.random() < 0.5)
    if plaza:
        hx, hy = (float(v) for v in rng.uniform(4.0, 6.0, 2))
    else:
        hx, hy = float(rng.uniform(3.0, 6.0)), float(rng.uniform(7.0, 10.0))
    styles = [_FacadeStyle(rng, shop_front=rng.random() < 0.5)
              for _ in range(int(rng.integers(3, 6)))]
    near, gaps, entrances = [], [], []
    if plaza:
        for axis, half, other in ((0, hx, hy), (1, hy, hx)):
            for sign in (-1, 1):
                blocks, streets = _frontage(rng, sign * half, axis, sign, -other, other, 1,
                                            (-other, other))
                near += blocks
                gaps += streets
                entrances += [(axis, sign, g[1 - axis], g[3 - axis]) for g in streets]
        for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            if rng.random() < 0.5:
                size = rng.uniform(6.0, 12.0, 2)
                xs = sorted((sx * hx, sx * (hx + size[0])))
                ys = sorted((sy * hy, sy * (hy + size[1])))
                near.append((xs[0], ys[0], xs[1], ys[1]))
        open_area = (-hx - 0.5, -hy - 0.5, hx + 0.5, hy + 0.5)
    else:
        for sign in (-1, 1):
            blocks, streets = _frontage(rng, sign * hx, 0, sign, -26.0, 26.0, 2, (-hy, hy))
            near += blocks
            gaps += streets
        open_area = (-hx - 0.5, -20.0, hx + 0.5, 20.0)
    far = _far_blocks(rng, near, open_area)
    by_style: list[list] = [[] for _ in styles]
    for (x0, y0, x1, y1), is_near in [(b, True) for b in near] + [(b, False) for b in far]:
        k = int(rng.integers(len(styles)))
        style = styles[k]
        floors = int(rng.integers(2, 7)) if is_near else int(rng.integers(3, 9))
        top = floors * style.storey + float(rng.uniform(0.2, 0.18 * style.storey))
        by_style[k].append(box_mesh((x0, y0, 0.0), (x1, y1, top), style.tile))
    floor = _Floor(hx, hy)
    kit = _Kit(rng, floor)
    roads: list[np.ndarray] = []
    for x0, y0, x1, y1 in gaps:                                # side streets' roads
        roads.append(floor_quad(x0, y0, x1, y1, 0.001))
    if plaza:
        _plaza(rng, kit, hx, hy, entrances)
    else:
        _street(rng, kit, hx, hy, roads)
    paving, tile = _paving(rng)
    asphalt = tinted("concrete", np.full(3, rng.uniform(0.28, 0.42)), 0.6)
    parts = [_ground(paving, tile)]
    for k, meshes in enumerate(by_style):
        if meshes:
            parts.append(solids_part(meshes, [texture_color(styles[k].texture)] * len(meshes),
                                     f"buildings{k}", True, styles[k].texture))
    if roads:
        roads_array = np.array(roads)
        parts.append(quads_part(roads_array, "road", texture=asphalt,
                                uvs=roads_array[..., :2] / 5.0))
    if kit.marks:
        parts.append(quads_part(np.array(kit.marks), "marks", colors=kit.mark_colors))
    if kit.solids:
        parts.append(solids_part(kit.solids, kit.solid_colors, "furniture", True))
    if kit.crowns:
        parts.append(solids_part(kit.crowns, kit.crown_colors, "crowns", False))
    if kit.water:
        parts.append(solids_part(kit.water, kit.water_colors, "water", False))
    return Scene(name="streets", bounds=((-hx, -hy), (hx, hy)), meshes=tuple(parts), fence=True,
                 ground_plane=False, sky_color=horizon, appearance=appearance,
                 metadata={"layout": "plaza" if plaza else "street"})
