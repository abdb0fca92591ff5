"""``long_corridors``: an indoor world of long corridors, new every episode (drawn from
the episode's random generator).

One straight corridor 12-30 m long, or two (12-24 m) meeting in an L or a T junction,
each 1.4-3 m wide, with walls 2.2-3 m high (no ceiling: the light grey indoor sky shows
above). Along the walls: recessed doors (0.85-1.2 m wide, 2-2.1 m high, painted in
varied colours or wood, in frames, with handles, sometimes a window pane and a sign),
doorways into rooms 1.5-3 m deep and 2-4 m wide (walls and floor in a style of their
own, a cabinet or a plant inside) and open alcoves 0.7-1.5 m deep; pilasters at a
regular pitch in some worlds, free-standing pillars down the middle of wide corridors;
benches, radiators, fire extinguishers, cabinets and potted plants on the floor;
notice boards with pinned sheets, posters and signs on the walls; the ends of the
corridors show a door, a frosted window or a notice board. Wherever the corridor narrows
beside a thing at least :data:`PASSAGE` metres stay free, and every room and alcove is
reached through an opening at least 0.9 m wide.

The walls are the faces of solid blocks that fill the rest of the bounds (and a band
:data:`OUTER` metres beyond), so no floor is enclosed out of reach; the robot bumps into
them, into the furniture, pillars and frames, not into pictures hung above its height
band. Randomised: the plan (shape, lengths, widths, openings), the wall style (a
texture composed per world: plaster, bricks or tiles, often a dado and a skirting, the
rooms' own), the floor (tiles, linoleum, wood, concrete), every colour, the counts of
everything, and the light and camera height
(:func:`~homing_gym.scenes.appearance.random_appearance`). ``scene.metadata``:
``"layout"`` (``"I"``, ``"L"`` or ``"T"``), ``"corridors"`` and ``"rooms"`` (their free
rectangles ((xmin, ymin), (xmax, ymax)) in scene coordinates).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from homing_gym.scenes.appearance import random_appearance
from homing_gym.scenes.base import Landmark, Scene
from homing_gym.scenes.families.built_parts import (box_mesh, floor_quad, prism_mesh,
                                                    quads_part, scaled, solids_part,
                                                    texture_color, tinted)
from homing_gym.scenes.random_nature import _lump

Rect = tuple[float, float, float, float]
#: Thickness (metres) of the walls between a corridor and its rooms.
WALL_T = 0.15
#: Depth (metres) of solid wall beyond the free floor's bounds.
OUTER = 0.3
#: Least width (metres) of the passage left beside anything standing in a corridor.
PASSAGE = 0.6
#: Least gap (metres) between two things standing along the same wall.
SPACING = 0.55
#: Wall materials: (shipped texture, metres its image spans, contrast).
WALL_MATERIALS = (("concrete", 2.0, 0.3), ("concrete", 2.0, 0.7), ("bricks_grey", 1.0, 0.5),
                  ("bricks_red", 1.0, 0.5), ("floor_tiles", 0.8, 2.0))
#: Lower-wall (dado) materials.
DADO_MATERIALS = (("wood_light", 0.6, 0.5), ("wood_dark", 0.6, 0.5), ("floor_tiles", 0.6, 2.5),
                  ("concrete", 2.0, 0.3))
#: Floor materials: (shipped texture, metres per repeat range, contrast).
FLOOR_MATERIALS = (("floor_tiles", (0.8, 1.8), 1.5), ("checker_dark", (1.2, 2.4), 0.5),
                   ("wood_light", (1.0, 1.6), 1.0), ("wood_dark", (1.0, 1.6), 1.0),
                   ("concrete", (2.0, 4.0), 0.8))
#: Pale paint for walls (RGB).
PAINT = ((0.92, 0.91, 0.86), (0.85, 0.88, 0.9), (0.9, 0.85, 0.72), (0.8, 0.86, 0.78),
         (0.88, 0.8, 0.78), (0.75, 0.76, 0.78), (0.95, 0.93, 0.88))
#: Paint of doors (RGB).
DOOR_COLORS = ((0.95, 0.95, 0.93), (0.7, 0.72, 0.75), (0.2, 0.35, 0.6), (0.25, 0.5, 0.35),
               (0.65, 0.18, 0.15), (0.85, 0.7, 0.25), (0.3, 0.3, 0.33), (0.45, 0.6, 0.7))
#: Wood of doors (RGB).
WOOD = ((0.6, 0.42, 0.25), (0.45, 0.3, 0.18), (0.75, 0.58, 0.38))
POSTER_TEXTURES = ("poster_a", "poster_b", "stripes_warm", "stripes_cool", "checker_green")


def _choice(rng: np.random.Generator, options):
    return options[int(rng.integers(len(options)))]


def _rgb(rng: np.random.Generator, base, spread: float = 0.08) -> tuple[float, float, float]:
    """``base`` varied in brightness and hue by up to ``spread``."""
    c = np.clip(np.asarray(base) * rng.uniform(1 - spread, 1 + spread)
                + rng.uniform(-spread / 2, spread / 2, 3), 0, 1)
    return tuple(float(v) for v in c)


@dataclass
class _Space:
    """A free rectangle of the plan (corridor, room or alcove) running along ``axis``
    (0: x), with walls on side ``-1`` (low) and ``+1`` (high) of the cross axis, and what
    stands along them, per side: ``floor`` things as (start, end, protrusion into the
    space), ``hanging`` things and ``kept`` spans (openings, junctions: nothing before
    them) as (start, end); ``middle``: free-standing things down the middle as (start,
    end, half width). ``passage``: the width (metres) a thing must leave free across the
    space beside it."""

    rect: Rect
    axis: int
    passage: float = PASSAGE
    floor: dict = field(default_factory=lambda: {-1: [], 1: []})
    hanging: dict = field(default_factory=lambda: {-1: [], 1: []})
    kept: dict = field(default_factory=lambda: {-1: [], 1: []})
    middle: list = field(default_factory=list)

    @property
    def span(self) -> tuple[float, float]:
        """Start and end (metres) along the axis."""
        return (self.rect[0], self.rect[2]) if self.axis == 0 else (self.rect[1], self.rect[3])

    @property
    def width(self) -> float:
        """Width (metres) across the axis."""
        return self.rect[3] - self.rect[1] if self.axis == 0 else self.rect[2] - self.rect[0]

    def wall(self, side: int) -> float:
        """The cross coordinate of the wall on ``side``."""
        lo, hi = (self.rect[1], self.rect[3]) if self.axis == 0 else (self.rect[0], self.rect[2])
        return hi if side > 0 else lo

    def point(self, side: int, s: float, d: float) -> tuple[float, float]:
        """The floor point at ``s`` along the axis, ``d`` metres from the wall on ``side``
        into the space (negative: into the wall)."""
        c = self.wall(side) - side * d
        return (s, c) if self.axis == 0 else (c, s)

    def normal(self, side: int) -> tuple[float, float]:
        """The unit normal of the wall on ``side``, into the space."""
        return (0.0, float(-side)) if self.axis == 0 else (float(-side), 0.0)

    def beyond(self, side: int, s0: float, s1: float, d0: float, d1: float) -> Rect:
        """The rectangle from ``s0`` to ``s1`` along the axis and from ``d0`` to ``d1``
        metres beyond the wall on ``side`` (out of the space; negative: into it)."""
        a, b = sorted((self.wall(side) + side * d0, self.wall(side) + side * d1))
        return (s0, a, s1, b) if self.axis == 0 else (a, s0, b, s1)

    def clear(self, side: int, a: float, b: float, margin: float) -> bool:
        """Whether ``[a, b]`` on ``side`` lies ``margin`` inside the span's ends and
        ``margin`` clear of the kept spans, the floor and the hanging things there."""
        lo, hi = self.span
        if a < lo + margin or b > hi - margin:
            return False
        spans = self.kept[side] + [f[:2] for f in self.floor[side]] + self.hanging[side]
        return all(b + margin <= s0 or a - margin >= s1 for s0, s1 in spans)

    def fits(self, side: int, a: float, b: float, protrusion: float) -> bool:
        """Whether a thing from ``a`` to ``b`` along the wall on ``side``, standing
        ``protrusion`` metres into the space, keeps :data:`SPACING` from the things
        beside it and leaves ``passage`` free across the space beside it."""
        lo, hi = self.span
        if a < lo + 0.05 or b > hi - 0.05 or protrusion > self.width - self.passage:
            return False

        def near(s0: float, s1: float, margin: float) -> bool:
            return not (b + margin <= s0 or a - margin >= s1)

        if (any(near(s0, s1, SPACING) for s0, s1, _ in self.floor[side])
                or any(near(s0, s1, 0.3) for s0, s1 in self.kept[side])
                or any(near(s0, s1, 0.05) for s0, s1 in self.hanging[side])):
            return False
        if any(near(s0, s1, SPACING) and protrusion + p > self.width - self.passage
               for s0, s1, p in self.floor[-side]):
            return False
        return all(not near(s0, s1, SPACING) or self.width / 2 - r - protrusion >= self.passage
                   for s0, s1, r in self.middle)


class _World:
    """What a world is built from, gathered as it is drawn: the free rectangles, the
    rooms, landmarks, and the mesh solids of each part, in plan coordinates."""

    def __init__(self, rng: np.random.Generator, height: float, style: dict):
        self.rng, self.height, self.style = rng, height, style
        self.free: list[Rect] = []
        self.rooms: list[tuple[_Space, int, tuple[float, float]]] = []  # room, side, doorway
        self.landmarks: list[Landmark] = []
        self.frames: list = []            # colliding plain solids: frames, pots, extinguishers
        self.frame_colors: list = []
        self.leaves: list = []
        self.leaf_colors: list = []
        self.radiators: list = []
        self.lintels: list[Rect] = []

    def solid(self, mesh, color) -> None:
        self.frames.append(mesh[:2])
        self.frame_colors.append(np.asarray(color, np.float64))

    def panel(self, point, normal, width: float, height: float, base: float, depth: float,
              color, texture: str | None, name: str) -> None:
        """A panel landmark ``width`` x ``height`` metres, its bottom ``base`` above the
        floor, its back on the wall at floor point ``point``, facing ``normal``."""
        nx, ny = normal
        off = depth / 2 + 0.003
        self.landmarks.append(Landmark(
            position=(point[0] + off * nx, point[1] + off * ny), shape="panel",
            extent=(width, depth), height=height, base=base,
            yaw=math.atan2(ny, nx) - math.pi / 2, color=(*color, 1.0), texture=texture,
            name=name))

    def box(self, point, normal, length: float, depth: float, height: float, color,
            texture: str | None, name: str, base: float = 0.0, off: float = 0.01) -> None:
        """A box landmark ``length`` along the wall and ``depth`` out from it, its back
        ``off`` metres from the wall at floor point ``point``."""
        nx, ny = normal
        d = depth / 2 + off
        self.landmarks.append(Landmark(
            position=(point[0] + d * nx, point[1] + d * ny), shape="box",
            extent=(length, depth), height=height, base=base,
            yaw=math.atan2(ny, nx) - math.pi / 2, color=(*color, 1.0), texture=texture,
            name=name))


def _plan(rng: np.random.Generator) -> tuple[str, list[_Space]]:
    """The corridors: one straight (I) or two meeting in an L or a T."""
    pick = rng.random()
    wa, wb = (float(v) for v in rng.uniform(1.4, 3.0, 2))
    if pick < 0.4:
        return "I", [_Space((0.0, 0.0, float(rng.uniform(12.0, 30.0)), wa), 0)]
    la, lb = (float(v) for v in rng.uniform(12.0, 24.0, 2))
    a = _Space((0.0, 0.0, la, wa), 0)
    if pick < 0.7:
        return "L", [a, _Space((la - wb, 0.0, la, lb), 1)]
    c = float(rng.uniform(3.0 + wb / 2, la - 3.0 - wb / 2))
    return "T", [a, _Space((c - wb / 2, 0.0, c + wb / 2, lb), 1)]


def _overlap(a: Rect, b: Rect, margin: float) -> bool:
    return (a[0] < b[2] + margin and b[0] < a[2] + margin and a[1] < b[3] + margin
            and b[1] < a[3] + margin)


def _inside(rect: Rect, outer: Rect) -> bool:
    return (rect[0] >= outer[0] and rect[1] >= outer[1] and rect[2] <= outer[2]
            and rect[3] <= outer[3])


def _box(rect: Rect, z0: float, z1: float, tile: tuple[float, float] = (1.0, 1.0)):
    """The closed box over floor rectangle ``rect`` from height ``z0`` to ``z1``."""
    return box_mesh((rect[0], rect[1], z0), (rect[2], rect[3], z1), tile)


def _ends(corridors: list[_Space]) -> list[tuple[_Space, int]]:
    """The corridors' dead ends, as (corridor, -1 for its start or +1 for its end), and
    keep their walls clear where corridors meet (0.6 m either side of the crossing)."""
    ends = []
    for c in corridors:
        for end, s in ((-1, c.span[0]), (1, c.span[1])):
            tip = (s - 0.01, c.wall(-1), s + 0.01, c.wall(1))
            tip = tip if c.axis == 0 else (tip[1], tip[0], tip[3], tip[2])
            if not any(d is not c and _overlap(tip, d.rect, 0.0) for d in corridors):
                ends.append((c, end))
        for d in corridors:
            if d is not c and _overlap(c.rect, d.rect, 0.0):
                lo, hi = max(c.span[0], d.rect[c.axis]), min(c.span[1], d.rect[c.axis + 2])
                for side in (-1, 1):
                    c.kept[side].append((lo - 0.6, hi + 0.6))
    return ends


def _frame(world: _World, space: _Space, side: int, a: float, b: float) -> None:
    """A frame (6 cm wide, 2 cm proud) round the opening from ``a`` to ``b`` along the
    wall on ``side``, up to the door height."""
    top, color = world.style["door_height"], world.style["frame"]
    for s0, s1 in ((a - 0.06, a), (b, b + 0.06)):
        world.solid(_box(space.beyond(side, s0, s1, -0.02, 0.0), 0.0, top + 0.06), color)
    world.solid(_box(space.beyond(side, a, b, -0.02, 0.0), top, top + 0.06), color)


def _door(world: _World, space: _Space, side: int, s: float, width: float,
          recess: float) -> None:
    """A door ``width`` metres wide from ``s`` along the wall on ``side``, ``recess``
    metres back from the wall face, in a frame, with a handle, sometimes a window pane
    and a sign over it."""
    rng, style = world.rng, world.style
    height, normal = style["door_height"], space.normal(side)
    mid = s + width / 2
    wood = style["wood_doors"] and rng.random() < 0.7
    color = _rgb(rng, _choice(rng, WOOD if wood else style["doors"]))
    world.panel(space.point(side, mid, -recess), normal, width - 0.02, height, 0.0, 0.04,
                color, None, "door")
    face = -recess + 0.043
    handle = s + 0.12 if rng.random() < 0.5 else s + width - 0.12
    world.box(space.point(side, handle, face), normal, 0.13, 0.05, 0.03, (0.75, 0.75, 0.72),
              None, "handle", base=float(rng.uniform(0.95, 1.05)), off=0.0)
    if rng.random() < 0.3:
        world.panel(space.point(side, mid, face), normal, float(rng.uniform(0.2, 0.4)),
                    float(rng.uniform(0.4, 0.7)), 1.2, 0.005, _rgb(rng, (0.2, 0.25, 0.3)),
                    None, "door window")
    if world.height - height > 0.4 and rng.random() < 0.6:
        world.panel(space.point(side, mid, 0.0), normal, float(rng.uniform(0.3, 0.5)),
                    float(rng.uniform(0.12, 0.2)), height + 0.12, 0.02,
                    _rgb(rng, _choice(rng, ((0.1, 0.55, 0.25), (0.92, 0.92, 0.9),
                                            (0.2, 0.3, 0.6)))), None, "sign")
    if recess > 0:
        world.lintels.append(space.beyond(side, s, s + width, 0.0, recess))
    _frame(world, space, side, s, s + width)


def _openings(world: _World, corridor: _Space, allowed: Rect) -> None:
    """Rooms behind doorways, open alcoves and recessed doors along ``corridor``'s
    walls, each in a free stretch of wall; a room or alcove only where it stays
    :data:`WALL_T` clear of every other free rectangle, inside ``allowed``."""
    rng = world.rng
    lo, hi = corridor.span
    for side in (-1, 1):
        for _ in range(int((hi - lo) / float(rng.uniform(2.0, 4.0)))):
            s = float(rng.uniform(lo, hi))
            pick = rng.random()
            if pick < 0.3:                                    # a room behind a doorway
                door = float(rng.uniform(0.9, 1.3))
                width = float(rng.uniform(max(2.0, door + 0.5), 4.0))
                depth = float(rng.uniform(1.5, 3.0))
                room = corridor.beyond(side, s, s + width, WALL_T, WALL_T + depth)
                d0 = s + float(rng.uniform(0.2, width - door - 0.2))
                if (corridor.clear(side, s, s + width, 0.3) and _inside(room, allowed)
                        and not any(_overlap(room, r, WALL_T - 0.01) for r in world.free)):
                    space = _Space(room, corridor.axis)
                    space.kept[-side].append((d0, d0 + door))
                    world.free += [room, corridor.beyond(side, d0, d0 + door, -0.01,
                                                         WALL_T + 0.01)]
                    corridor.kept[side].append((d0, d0 + door))
                    world.rooms.append((space, side, (d0, d0 + door)))
                    world.lintels.append(corridor.beyond(side, d0, d0 + door, 0.0, WALL_T))
                    _frame(world, corridor, side, d0, d0 + door)
            elif pick < 0.45:                                 # an open alcove
                width, depth = float(rng.uniform(1.2, 2.5)), float(rng.uniform(0.7, 1.5))
                alcove = corridor.beyond(side, s, s + width, -0.01, depth)
                if (corridor.clear(side, s, s + width, 0.3) and _inside(alcove, allowed)
                        and not any(_overlap(alcove, r, WALL_T) for r in world.free
                                    if r != corridor.rect)):
                    world.free.append(alcove)
                    corridor.kept[side].append((s, s + width))
                    if rng.random() < 0.7:
                        space = _Space(corridor.beyond(side, s, s + width, 0.0, depth),
                                       corridor.axis, passage=0.05)
                        _things(world, space, (side,), 1)
            else:                                             # a closed door, recessed
                width = float(rng.uniform(0.85, 1.2))
                recess = float(rng.uniform(0.06, 0.12))
                if corridor.clear(side, s, s + width, 0.3):
                    world.free.append(corridor.beyond(side, s, s + width, -0.01, recess))
                    corridor.kept[side].append((s, s + width))
                    _door(world, corridor, side, s, width, recess)


def _pillars(world: _World, corridor: _Space) -> None:
    """Pilasters at a regular pitch along both walls (some worlds), and pillars down
    the middle of a wide corridor (some of those)."""
    rng = world.rng
    lo, hi = corridor.span
    if rng.random() < 0.35:
        width, depth = float(rng.uniform(0.3, 0.5)), float(rng.uniform(0.1, 0.25))
        color = _rgb(rng, world.style["wall_color"] * rng.uniform(0.75, 1.0))
        pitch = float(rng.uniform(3.0, 5.0))
        for s in np.arange(lo + rng.uniform(0.5, pitch), hi - 0.5, pitch):
            for side in (-1, 1):
                a, b = float(s) - width / 2, float(s) + width / 2
                if corridor.fits(side, a, b, depth):
                    corridor.floor[side].append((a, b, depth))
                    world.box(corridor.point(side, float(s), 0.0), corridor.normal(side), width,
                              depth, world.height, color, None, "pilaster", off=0.0)
    if corridor.width >= 2.4 and rng.random() < 0.5:
        r = float(rng.uniform(0.15, 0.25))
        round_ = rng.random() < 0.5
        color = _rgb(rng, _choice(rng, ((0.8, 0.8, 0.78), (0.6, 0.6, 0.62), (0.7, 0.55, 0.4))))
        pitch = float(rng.uniform(3.0, 6.0))
        for s in np.arange(lo + rng.uniform(1.5, pitch), hi - 1.5, pitch):
            a, b = float(s) - r, float(s) + r
            if all(corridor.fits(side, a, b, 0.0) for side in (-1, 1)) and not any(
                    not (b + SPACING <= s0 or a - SPACING >= s1) and
                    corridor.width / 2 - r - p < PASSAGE
                    for side in (-1, 1) for s0, s1, p in corridor.floor[side]):
                corridor.middle.append((a, b, r))
                x, y = corridor.point(-1, float(s), corridor.width / 2)
                if round_:
                    world.solid(prism_mesh((x, y), r, 0.0, world.height, 16), color)
                else:
                    world.landmarks.append(Landmark(position=(x, y), shape="box",
                                                    extent=(2 * r, 2 * r),
                                                    height=world.height,
                                                    color=(*color, 1.0), name="pillar"))


def _things(world: _World, space: _Space, sides: tuple[int, ...], count: int) -> None:
    """Up to ``count`` things along the walls of ``space`` on ``sides``: benches,
    radiators, fire extinguishers, cabinets, potted plants on the floor; notice boards
    and posters on the wall."""
    rng = world.rng
    lo, hi = space.span
    for _ in range(count):
        side = int(_choice(rng, sides))
        kind = _choice(rng, ("bench", "radiator", "extinguisher", "cabinet", "plant",
                             "board", "poster", "poster"))
        normal = space.normal(side)
        if kind in ("board", "poster"):
            width = float(rng.uniform(0.8, 1.6) if kind == "board" else rng.uniform(0.4, 0.9))
            height = float(min(rng.uniform(0.6, 1.0), world.height - 1.3))
            s = float(rng.uniform(lo, max(lo, hi - width)))
            if not space.clear(side, s, s + width, 0.1):
                continue
            space.hanging[side].append((s, s + width))
            base = float(rng.uniform(0.9, 1.2))
            if kind == "poster":
                world.panel(space.point(side, s + width / 2, 0.0), normal, width, height, base,
                            0.01, _rgb(rng, (0.9, 0.9, 0.9), 0.1), _choice(rng, POSTER_TEXTURES),
                            "poster")
                continue
            board = _choice(rng, ((0.72, 0.55, 0.35), (0.95, 0.95, 0.93), (0.3, 0.45, 0.35)))
            world.panel(space.point(side, s + width / 2, 0.0), normal, width, height, base,
                        0.025, _rgb(rng, board), None, "notice board")
            for _ in range(int(rng.integers(2, 6))):
                w, h = float(rng.uniform(0.15, 0.25)), float(rng.uniform(0.2, 0.3))
                at = float(rng.uniform(s + w / 2 + 0.03, s + width - w / 2 - 0.03))
                world.panel(space.point(side, at, 0.028), normal, w, h,
                            base + float(rng.uniform(0.03, height - h - 0.03)), 0.004,
                            _rgb(rng, _choice(rng, ((0.97, 0.97, 0.95), (0.95, 0.9, 0.5),
                                                    (0.7, 0.85, 0.95), (0.95, 0.75, 0.8)))),
                            _choice(rng, (None, None, "poster_a", "poster_b")), "sheet")
            continue
        length, depth = {"bench": (rng.uniform(1.0, 2.0), rng.uniform(0.4, 0.5)),
                         "radiator": (rng.uniform(0.6, 1.6), 0.13),
                         "extinguisher": (0.2, 0.2),
                         "cabinet": (rng.uniform(0.6, 1.6), rng.uniform(0.35, 0.6)),
                         "plant": (0.6, 0.6)}[kind]
        length, depth = float(length), float(depth)
        s = float(rng.uniform(lo, max(lo, hi - length)))
        if not space.fits(side, s, s + length, depth + 0.01):
            continue
        space.floor[side].append((s, s + length, depth + 0.01))
        mid = s + length / 2
        if kind == "bench":
            wood = rng.random() < 0.6
            world.box(space.point(side, mid, 0.0), normal, length, depth,
                      float(rng.uniform(0.42, 0.48)),
                      _rgb(rng, (0.95, 0.95, 0.95) if wood else (0.35, 0.4, 0.45), 0.1),
                      _choice(rng, ("wood_light", "wood_dark")) if wood else None, "bench")
        elif kind == "radiator":
            base = float(rng.uniform(0.1, 0.15))
            world.radiators.append(_box(space.beyond(side, s, s + length, -0.13, -0.03), base,
                                        base + float(rng.uniform(0.5, 0.7)), (0.08, 0.6)))
        elif kind == "extinguisher":
            x, y = space.point(side, mid, 0.1)
            world.solid(prism_mesh((x, y), 0.08, 0.0, float(rng.uniform(0.45, 0.6)), 10),
                        _rgb(rng, (0.8, 0.08, 0.06)))
            if space.clear(side, mid - 0.12, mid + 0.12, 0.0):
                world.panel(space.point(side, mid, 0.0), normal, 0.2, 0.2, 1.5, 0.01,
                            (0.85, 0.1, 0.08), None, "extinguisher sign")
        elif kind == "cabinet":
            world.box(space.point(side, mid, 0.0), normal, length, depth,
                      float(min(rng.uniform(0.9, 2.0), world.height - 0.2)),
                      _rgb(rng, _choice(rng, ((0.6, 0.62, 0.65), (0.85, 0.83, 0.78),
                                              (0.35, 0.45, 0.6), (0.55, 0.4, 0.28)))),
                      None, "cabinet")
        else:
            x, y = space.point(side, mid, 0.3)
            r = float(rng.uniform(0.15, 0.22))
            pot = float(rng.uniform(0.3, 0.5))
            world.solid(prism_mesh((x, y), r, 0.0, pot, 10),
                        _rgb(rng, _choice(rng, ((0.65, 0.35, 0.22), (0.9, 0.9, 0.88),
                                                (0.25, 0.25, 0.27)))))
            leaves = _lump(rng, (x, y), (r + 0.06, r + 0.06, float(rng.uniform(0.25, 0.5))))
            world.leaves.append((leaves[0] + [0.0, 0.0, pot - 0.05], leaves[1]))
            world.leaf_colors.append(np.array(_rgb(rng, (0.2, 0.5, 0.2), 0.2)))


def _end(world: _World, corridor: _Space, end: int) -> None:
    """The end wall of ``corridor`` (``end`` -1: at its start, +1: at its end): a door
    under an exit sign, a frosted window, a notice board or a poster."""
    rng = world.rng
    lo, hi = corridor.span
    s = lo if end < 0 else hi
    middle = corridor.point(-1, s, corridor.width / 2)
    normal = (-float(end), 0.0) if corridor.axis == 0 else (0.0, -float(end))
    pick = rng.random()
    if pick < 0.35:
        width = min(float(rng.uniform(0.9, 1.6)), corridor.width - 0.3)
        world.panel(middle, normal, width, world.style["door_height"], 0.0, 0.04,
                    _rgb(rng, _choice(rng, world.style["doors"])), None, "end door")
        if world.height - world.style["door_height"] > 0.35:
            world.panel(middle, normal, 0.4, 0.15, world.style["door_height"] + 0.1, 0.03,
                        (0.1, 0.6, 0.25), None, "exit sign")
    elif pick < 0.6:
        width = min(float(rng.uniform(0.8, 2.0)), corridor.width - 0.3)
        world.panel(middle, normal, width, world.height - 1.2, 0.9, 0.03,
                    _rgb(rng, (0.88, 0.92, 0.95), 0.05), None, "window")
    elif pick < 0.85:
        world.panel(middle, normal, min(float(rng.uniform(0.8, 1.5)), corridor.width - 0.3),
                    float(min(rng.uniform(0.6, 1.0), world.height - 1.3)), 1.0, 0.025,
                    _rgb(rng, (0.72, 0.55, 0.35)), None, "notice board")
    else:
        world.panel(middle, normal, min(float(rng.uniform(0.5, 1.0)), corridor.width - 0.3),
                    float(min(rng.uniform(0.7, 1.1), world.height - 1.2)), 0.9, 0.01,
                    _rgb(rng, (0.9, 0.9, 0.9)), _choice(rng, POSTER_TEXTURES), "poster")


def _wall_texture(rng: np.random.Generator, height: float) -> tuple[np.ndarray, float, np.ndarray]:
    """A wall texture (uint8, 256 x 128) spanning the wall's ``height`` once and its
    metres per repeat along the wall: plaster, bricks or tiles, often a dado with a rail
    below 0.8-1.3 m, a skirting; and the upper wall's colour (RGB)."""
    tile = float(rng.uniform(1.0, 2.0))
    name, metres, contrast = _choice(rng, WALL_MATERIALS)
    color = np.array(_rgb(rng, _choice(rng, PAINT)))
    tint = np.full(3, rng.uniform(0.8, 1.05)) if name == "bricks_red" else color
    image = scaled(tinted(name, tint, contrast), (tile / metres, height / metres), (256, 128))
    if rng.random() < 0.6:
        dado = float(rng.uniform(0.8, 1.3))
        row = int(256 * (1 - dado / height))
        name, metres, contrast = _choice(rng, DADO_MATERIALS)
        lower = _rgb(rng, _choice(rng, PAINT) if name != "concrete" else
                     _choice(rng, ((0.55, 0.6, 0.7), (0.6, 0.7, 0.6), (0.7, 0.6, 0.5))))
        panel = tinted(name, lower, contrast)
        if name.startswith("wood"):                   # panelling: upright boards
            panel = np.ascontiguousarray(
                _planks(rng, texture_color(panel)).transpose(1, 0, 2))
        image[row:] = scaled(panel, (tile / metres, height / metres), (256, 128))[row:]
        image[row - 3:row] = np.clip(255 * np.asarray(_rgb(rng, (0.5, 0.45, 0.4), 0.4)), 0, 255)
    skirting = max(2, int(256 * float(rng.uniform(0.06, 0.12)) / height))
    image[-skirting:] = np.clip(255 * np.asarray(_rgb(rng, _choice(rng, (
        (0.2, 0.2, 0.22), (0.45, 0.32, 0.2), (0.85, 0.85, 0.82))))), 0, 255)
    return image, tile, color


def _floor_texture(rng: np.random.Generator) -> tuple[np.ndarray, float]:
    """A floor texture (tinted shipped texture; wood laid as planks) and its metres per
    repeat."""
    name, tiles, contrast = _choice(rng, FLOOR_MATERIALS)
    if name.startswith("wood"):
        wood = texture_color(tinted(name, np.full(3, rng.uniform(0.6, 0.95))))
        return _planks(rng, wood), float(rng.uniform(*tiles))
    tint = _rgb(rng, _choice(rng, ((0.8, 0.8, 0.78), (0.7, 0.72, 0.75), (0.8, 0.72, 0.6),
                                   (0.6, 0.7, 0.65), (0.85, 0.82, 0.75))), 0.15)
    return tinted(name, tint, contrast), float(rng.uniform(*tiles))


def _planks(rng: np.random.Generator, rgb) -> np.ndarray:
    """Eight wooden planks (uint8, 128 x 128) of colour ``rgb`` (0-1): each a little
    lighter or darker, its grain lines running along it with a gentle bend, dark joints
    between planks and one end joint each."""
    y = (np.arange(16)[:, None] + 0.5) / 16
    x = (np.arange(128)[None, :] + 0.5) / 128
    image = np.empty((128, 128, 3))
    for k in range(8):
        lines, bend = rng.uniform(1.5, 3.5), rng.uniform(0.1, 0.5)
        grain = 0.86 + 0.14 * np.sin(2 * math.pi * (
            lines * y + bend * np.sin(2 * math.pi * x + rng.uniform(0, 2 * math.pi))))
        band = grain[..., None] * np.asarray(rgb) * rng.uniform(0.85, 1.15)
        band[-1] *= 0.5                                   # the joint to the next plank
        band[:, int(rng.integers(0, 128))] *= 0.5         # an end joint
        image[16 * k:16 * k + 16] = band
    return np.clip(255 * image, 0, 255).astype(np.uint8)


def _blocked(free: list[Rect], outer: Rect) -> list[Rect]:
    """Rectangles that fill ``outer`` less the union of ``free``: cells between the
    rectangles' edges, merged into runs along x and the runs into stacks along y."""
    xs = np.unique(np.round([v for r in free for v in r[0::2]] + [outer[0], outer[2]], 6))
    ys = np.unique(np.round([v for r in free for v in r[1::2]] + [outer[1], outer[3]], 6))
    cx, cy = (xs[:-1] + xs[1:]) / 2, (ys[:-1] + ys[1:]) / 2
    rects = np.array(free)
    inside = ((cx[:, None, None] > rects[:, 0]) & (cx[:, None, None] < rects[:, 2])
              & (cy[None, :, None] > rects[:, 1]) & (cy[None, :, None] < rects[:, 3]))
    blocked = ~inside.any(axis=2)                    # (x cells, y cells)
    done: list[Rect] = []
    open_runs: dict[tuple[int, int], int] = {}       # run (i0, i1) -> first row
    for j in range(len(cy) + 1):
        runs = set()
        if j < len(cy):
            i = 0
            while i < len(cx):
                if blocked[i, j]:
                    k = i
                    while k + 1 < len(cx) and blocked[k + 1, j]:
                        k += 1
                    runs.add((i, k + 1))
                    i = k + 1
                else:
                    i += 1
        for run in sorted(open_runs):
            if run not in runs:
                j0 = open_runs.pop(run)
                done.append((float(xs[run[0]]), float(ys[j0]), float(xs[run[1]]), float(ys[j])))
        for run in sorted(runs):
            open_runs.setdefault(run, j)
    return done


def _shifted(mesh: tuple, shift: np.ndarray) -> tuple:
    """A mesh ``(vertices, faces[, uvs])`` moved by ``shift`` (x, y metres)."""
    return (mesh[0] + [shift[0], shift[1], 0.0], *mesh[1:])


def long_corridors_scene(rng: np.random.Generator) -> Scene:
    """Draw a ``long_corridors`` world from ``rng`` (see the module doc)."""
    horizon, appearance = random_appearance(rng, outdoor=False)
    layout, corridors = _plan(rng)
    height = float(rng.uniform(2.2, 3.0))
    wall, tile, wall_color = _wall_texture(rng, height)
    doors = [DOOR_COLORS[k] for k in rng.choice(len(DOOR_COLORS), int(rng.integers(1, 4)),
                                                replace=False)]
    style = {"door_height": float(rng.uniform(2.0, min(2.1, height - 0.15))),
             "frame": np.array(_rgb(rng, _choice(rng, ((0.95, 0.95, 0.93), (0.5, 0.35, 0.22),
                                                       (0.3, 0.3, 0.32), (0.7, 0.72, 0.75))))),
             "doors": doors, "wood_doors": bool(rng.random() < 0.3), "wall_color": wall_color}
    world = _World(rng, height, style)
    world.free = [c.rect for c in corridors]
    ends = _ends(corridors)
    xs = [v for c in corridors for v in c.rect[0::2]]
    ys = [v for c in corridors for v in c.rect[1::2]]
    ex, ey = (min(3.5, (29.9 - (max(v) - min(v))) / 2) for v in (xs, ys))
    allowed = (min(xs) - ex, min(ys) - ey, max(xs) + ex, max(ys) + ey)
    for corridor in corridors:
        _openings(world, corridor, allowed)
    for corridor in corridors:
        _pillars(world, corridor)
    for corridor, end in ends:
        _end(world, corridor, end)
    for corridor in corridors:
        lo, hi = corridor.span
        _things(world, corridor, (-1, 1), int((hi - lo) / float(rng.uniform(1.0, 2.0))))
    room_walls = [_wall_texture(rng, height)[:2] for _ in range(int(rng.integers(1, 3)))]
    room_floors = [_floor_texture(rng) for _ in range(int(rng.integers(1, 3)))]
    veneers: list[list] = [[] for _ in room_walls]
    patches: list[list] = [[] for _ in room_floors]
    for space, side, (d0, d1) in world.rooms:
        _things(world, space, (side,), int(rng.integers(0, 3)))
        _things(world, space, (-1, 1), int(rng.integers(0, 2)))
        veneers[int(rng.integers(len(room_walls)))].append((space, side, (d0, d1)))
        patches[int(rng.integers(len(room_floors)))].append(space.rect)

    (bx0, by0) = (min(r[0] for r in world.free), min(r[1] for r in world.free))
    (bx1, by1) = (max(r[2] for r in world.free), max(r[3] for r in world.free))
    shift = np.array([-(bx0 + bx1) / 2, -(by0 + by1) / 2])
    outer = (bx0 - OUTER, by0 - OUTER, bx1 + OUTER, by1 + OUTER)
    walls = [_box(r, 0.0, height, (tile, height)) for r in _blocked(world.free, outer)]
    walls += [_box(r, style["door_height"], height, (tile, height)) for r in world.lintels]
    floor, floor_tile = _floor_texture(rng)
    quad = floor_quad(*outer, 0.0) + [shift[0], shift[1], 0.0]
    parts = [quads_part(quad, "floor", texture=floor, uvs=quad[:, :2] / floor_tile),
             solids_part([_shifted(m, shift) for m in walls],
                         [texture_color(wall)] * len(walls), "walls", True, wall)]
    for (texture, wall_tile), rooms in zip(room_walls, veneers):
        quads, uvs = _veneers(rooms, height, wall_tile, shift)
        if quads:
            parts.append(quads_part(quads, "room walls", texture=texture, uvs=uvs))
    for (texture, patch_tile), rects in zip(room_floors, patches):
        if rects:
            quads = np.array([floor_quad(*r, 0.001) for r in rects]) + [shift[0], shift[1], 0.0]
            parts.append(quads_part(quads, "room floors", texture=texture,
                                    uvs=quads[..., :2] / patch_tile))
    if world.frames:
        parts.append(solids_part([_shifted(m, shift) for m in world.frames], world.frame_colors,
                                 "fittings", True))
    if world.radiators:
        parts.append(solids_part([_shifted(m, shift) for m in world.radiators],
                                 [np.full(3, 0.85)] * len(world.radiators), "radiators", True,
                                 _radiator_texture(rng)))
    if world.leaves:
        parts.append(solids_part([_shifted(m, shift) for m in world.leaves], world.leaf_colors,
                                 "leaves", False))
    landmarks = tuple(replace(lm, position=(lm.position[0] + shift[0], lm.position[1] + shift[1]))
                      for lm in world.landmarks)

    def placed(rect: Rect) -> tuple:
        return ((float(rect[0] + shift[0]), float(rect[1] + shift[1])),
                (float(rect[2] + shift[0]), float(rect[3] + shift[1])))

    half = ((bx1 - bx0) / 2, (by1 - by0) / 2)
    return Scene(name="long_corridors", bounds=((-half[0], -half[1]), half), landmarks=landmarks,
                 meshes=tuple(parts), fence=True, ground_plane=False, sky_color=horizon,
                 appearance=appearance,
                 metadata={"layout": layout, "corridors": [placed(c.rect) for c in corridors],
                           "rooms": [placed(space.rect) for space, _, _ in world.rooms]})


def _veneers(rooms: list, height: float, tile: float, shift: np.ndarray) -> tuple[list, list]:
    """The faces (quads 3 mm in front of the walls, floor to ``height``) and uvs of the
    rooms' own wall covering, leaving each room's doorway open."""
    quads, uvs = [], []
    for space, side, (d0, d1) in rooms:
        x0, y0, x1, y1 = space.rect
        e = 0.003
        x0, y0, x1, y1 = x0 + e, y0 + e, x1 - e, y1 - e
        corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
        for k in range(4):
            a, b = np.array(corners[k]), np.array(corners[(k + 1) % 4])
            pieces = [(a, b)]
            along = 0 if a[1] == b[1] else 1
            front = space.wall(-side)
            if space.axis == along and abs((a[1 - along]) - front) < 0.01:
                direction = np.sign(b[along] - a[along])
                cut0, cut1 = sorted((d0, d1), key=lambda v: direction * v)
                p, q = a.copy(), b.copy()
                p[along], q[along] = cut0, cut1
                pieces = [(a, p), (q, b)]
            for p, q in pieces:
                length = float(np.linalg.norm(q - p))
                if length < 0.01:
                    continue
                quads.append([(*(p + shift), 0.0), (*(q + shift), 0.0), (*(q + shift), height),
                              (*(p + shift), height)])
                uvs.append([(0.0, 0.0), (length / tile, 0.0), (length / tile, 1.0), (0.0, 1.0)])
    return quads, uvs


def _radiator_texture(rng: np.random.Generator) -> np.ndarray:
    """Radiator fins: light and shaded columns (uint8, 16 x 16), one fin per repeat."""
    paint = np.asarray(_rgb(rng, (0.92, 0.92, 0.9), 0.05)) * 255
    image = np.broadcast_to(paint, (16, 16, 3)).copy()
    image[:, 10:] *= 0.6
    return np.clip(image, 0, 255).astype(np.uint8)
