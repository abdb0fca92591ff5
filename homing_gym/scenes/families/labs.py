"""``labs``: one cluttered laboratory hall, new every episode (drawn from the episode's
random generator, so ``reset(seed=...)`` reproduces it).

A rectangular hall of 6-12 x 5-9 m inside walls 2-3 m high (pale paint, wall tiles,
concrete or brick, tinted), on a tiled, concrete or vinyl floor. Along the walls, with
little room between: lab benches (casework 0.86-0.95 m high with a worktop, instruments
and bottles on it and often a cupboard above, or open benches on a frame with a lower
shelf), fume hoods (1.2-1.8 m wide, up to 2.3 m high, a dark sash), open shelving units
(1.6-2.1 m high) full of boxes, fridges, tall cabinets, gas cylinders and stacks of boxes.
In the middle stand one to three island benches (1.8-3.6 x 1.2-1.5 m, often with a
reagent rack on top) with stools round them, trolleys with boxes on their trays, more
stools, and many boxes of many sizes (0.15-0.7 m) and colours on the floor, in heaps and
stacks; posters, signs and whiteboards hang on the walls, windows on some.

The robot bumps into walls, benches, hoods, fridges and cabinets (landmarks) and into
shelving, open benches, stools and trolleys as a whole (their low rails and trays,
:mod:`~homing_gym.scenes.families.indoor_parts`), gas cylinders and floor boxes (mesh
parts); what stands on benches and shelves is above it. There is much more clutter per
square metre than in ``offices``, yet a piece is kept only if every part of the floor
stays reachable through aisles at least 0.6 m wide (:class:`~homing_gym.scenes.families.
indoor_parts.FloorPlan`). Sizes, counts, layout, colours, textures and the world's
appearance (:func:`~homing_gym.scenes.appearance.random_appearance`, indoors) are drawn
per world. ``scene.metadata`` holds ``islands`` and ``floor_boxes``: the floor rectangles
(xmin, ymin, xmax, ymax) of the island benches and of the boxes (and piles) standing free.
"""

from __future__ import annotations

import math

import numpy as np

from homing_gym.scenes.appearance import random_appearance
from homing_gym.scenes.base import Landmark, Scene
from homing_gym.scenes.families.indoor_parts import (
    Capsule, FloorPlan, Furnishing, Piece, Rect, against_wall, box, box_landmark, cart,
    cylinder, finish, grown, outer_walls, shade, shelving, stool, table, wall_decor,
    wall_finishes, wall_length, windows)

WALL_TEXTURES = ("floor_tiles", "concrete", "bricks_grey", "checker_green")
FLOOR_TEXTURES = ("floor_tiles", "concrete", "checker_dark")
CASEWORK_TEXTURES = ("wood_light", "wood_dark", "concrete")
#: Colours (RGB) of floor boxes, crates and instruments: cardboard, white, grey, blue,
#: red, yellow, green, black, orange.
BOX_COLOURS = ((0.62, 0.47, 0.3), (0.9, 0.9, 0.88), (0.55, 0.56, 0.58), (0.2, 0.35, 0.7),
               (0.7, 0.15, 0.12), (0.88, 0.72, 0.15), (0.2, 0.5, 0.3), (0.12, 0.12, 0.13),
               (0.88, 0.45, 0.1))
#: Instrument colours: white, beige, grey, black, blue.
INSTRUMENTS = ((0.9, 0.9, 0.88), (0.82, 0.78, 0.68), (0.55, 0.56, 0.58), (0.12, 0.12, 0.13),
               (0.2, 0.35, 0.7))
#: Worktop colours: black and grey resin, white laminate, beech.
WORKTOPS = ((0.1, 0.1, 0.11), (0.35, 0.36, 0.38), (0.88, 0.88, 0.86), (0.75, 0.6, 0.42))
#: Gas cylinder colours: grey, green, blue, black, maroon, white.
CYLINDERS = ((0.5, 0.5, 0.52), (0.2, 0.45, 0.25), (0.2, 0.3, 0.6), (0.1, 0.1, 0.1),
             (0.45, 0.12, 0.12), (0.9, 0.9, 0.9))


def _colour(rng: np.random.Generator, choices) -> tuple[float, float, float]:
    """One of ``choices`` (RGB), shaded a little."""
    return shade(rng, choices[rng.integers(len(choices))], 0.07)


def _wall_yaw(side: int) -> float:
    """Yaw (radians) of a panel facing into the room from wall ``side`` (0 south, 1 east,
    2 north, 3 west)."""
    return (0.0, math.pi / 2, math.pi, -math.pi / 2)[side]


def _items_on(rng: np.random.Generator, rect: Rect, z: float, count: int,
              bottles: float = 0.45, palette=INSTRUMENTS) -> list:
    """Up to ``count`` things standing on the surface ``rect`` at height ``z``, as
    ``on_top`` solids: a bottle (a slim prism) with probability ``bottles``, otherwise an
    instrument or box (0.15-0.5 m) in a colour from ``palette``."""
    x0, y0, x1, y1 = rect
    solids = []
    for _ in range(count):
        if rng.random() < bottles:
            r = float(rng.uniform(0.03, 0.06))
            if x1 - x0 < 2 * r + 0.04 or y1 - y0 < 2 * r + 0.04:
                continue
            c = (rng.uniform(x0 + r + 0.02, x1 - r - 0.02),
                 rng.uniform(y0 + r + 0.02, y1 - r - 0.02))
            glass = shade(rng, (0.65, 0.8, 0.85) if rng.random() < 0.6 else (0.5, 0.3, 0.15), 0.1)
            solids.append(("on_top", cylinder(c, r, z, z + float(rng.uniform(0.1, 0.3)), 6),
                           glass))
        else:
            w, d = float(rng.uniform(0.15, 0.5)), float(rng.uniform(0.15, 0.4))
            if x1 - x0 < w + 0.04 or y1 - y0 < d + 0.04:
                continue
            cx = rng.uniform(x0 + w / 2 + 0.02, x1 - w / 2 - 0.02)
            cy = rng.uniform(y0 + d / 2 + 0.02, y1 - d / 2 - 0.02)
            solids.append(("on_top", box((cx - w / 2, cy - d / 2, cx + w / 2, cy + d / 2), z,
                                         z + float(rng.uniform(0.12, 0.45))),
                           _colour(rng, palette)))
    return solids


def _bench(rng: np.random.Generator, rect: Rect, side: int | None, height: float,
           wall_height: float, style: dict) -> Piece:
    """A lab bench over ``rect``, ``height`` metres high: casework (a box landmark) with a
    worktop and things on it, against wall ``side`` often with a cupboard above (base
    1.45-1.6 m), or (one in four) an open bench on a frame with a lower shelf and boxes
    on it."""
    x0, y0, x1, y1 = rect
    if rng.random() < 0.25:
        shelf = float(rng.uniform(0.12, 0.25))
        piece = table(rect, height, style["worktop"], style["metal"], shelf=shelf)
        piece.solids += _items_on(rng, grown(rect, -0.05), shelf + 0.02,
                                  int(rng.integers(0, 3)), bottles=0.0, palette=BOX_COLOURS)
    else:
        piece = Piece(footprint=rect, blocking=[rect],
                      landmarks=[box_landmark(rect, height - 0.03, "bench", **style["casework"])],
                      solids=[("on_top", box(rect, height - 0.03, height), style["worktop"])])
    piece.solids += _items_on(rng, rect, height, int(rng.integers(1, 6)))
    base = float(rng.uniform(1.45, 1.6))
    if side is not None and rng.random() < 0.6 and base + 0.45 < wall_height - 0.05:
        high = float(rng.uniform(0.45, min(0.8, wall_height - 0.05 - base)))
        above = {0: (x0, y0, x1, y0 + 0.32), 1: (x1 - 0.32, y0, x1, y1),
                 2: (x0, y1 - 0.32, x1, y1), 3: (x0, y0, x0 + 0.32, y1)}[side]
        piece.landmarks.append(box_landmark(above, high, "cupboard", base=base,
                                            **style["cupboard"]))
    return piece


def _fume_hood(rng: np.random.Generator, rect: Rect, side: int, wall_height: float) -> Piece:
    """A fume hood over ``rect`` against wall ``side``: a pale box up to 2.3 m high with
    a dark glass sash (a panel on its front, 0.85-1.65 m up)."""
    x0, y0, x1, y1 = rect
    height = float(min(wall_height - 0.05, rng.uniform(2.0, 2.3)))
    hood = box_landmark(rect, height, "fume_hood", shade(rng, (0.85, 0.86, 0.84), 0.08) + (1.0,))
    width = (x1 - x0 if side % 2 == 0 else y1 - y0) - 0.2
    yaw = _wall_yaw(side)
    nx, ny = -math.sin(yaw), math.cos(yaw)          # out of its front
    front = {0: ((x0 + x1) / 2, y1), 1: (x0, (y0 + y1) / 2), 2: ((x0 + x1) / 2, y0),
             3: (x1, (y0 + y1) / 2)}[side]
    sash = Landmark(position=(front[0] - 0.009 * nx, front[1] - 0.009 * ny), shape="panel",
                    extent=(width, 0.02), height=0.8, base=0.85, yaw=yaw,
                    color=shade(rng, (0.25, 0.3, 0.35), 0.05) + (1.0,), name="sash")
    return Piece(footprint=rect, blocking=[rect], landmarks=[hood, sash])


def _shelves(rng: np.random.Generator, rect: Rect, style: dict) -> Piece:
    """An open shelving unit over ``rect``, its boards partly filled with boxes."""
    height, boards = float(rng.uniform(1.6, 2.1)), int(rng.integers(4, 7))
    piece = shelving(rect, height, boards, style["metal"], style["board"])
    x0, y0, x1, y1 = rect
    along_x = x1 - x0 >= y1 - y0
    levels = [float(v) for v in np.linspace(0.08, height - 0.05, boards)[:-1] + 0.025]
    gap = float(np.diff(levels)[0]) if len(levels) > 1 else 0.3
    for z in levels:
        u, end = (x0, x1) if along_x else (y0, y1)
        u += float(rng.uniform(0.03, 0.2))
        while True:
            w = float(rng.uniform(0.15, 0.45))
            if u + w > end - 0.03:
                break
            if rng.random() < 0.75:
                depth = float(rng.uniform(0.2, 1.0)) * ((y1 - y0) if along_x else (x1 - x0)) - 0.02
                spot = ((u, y0 + 0.01, u + w, y0 + 0.01 + depth) if along_x
                        else (x0 + 0.01, u, x0 + 0.01 + depth, u + w))
                high = float(rng.uniform(0.4, 0.95)) * gap
                piece.solids.append(("on_top", box(spot, z, z + high), _colour(rng, BOX_COLOURS)))
            u += w + float(rng.uniform(0.01, 0.15))
    return piece


def _gas_cylinders(rng: np.random.Generator, rect: Rect) -> Piece:
    """Two to four gas cylinders (0.1-0.12 m in radius, 1.3-1.6 m high, capped) in a
    row along floor rectangle ``rect``."""
    x0, y0, x1, y1 = rect
    along_x = x1 - x0 >= y1 - y0
    count = int(rng.integers(2, 5))
    piece = Piece(footprint=rect)
    for i in range(count):
        t = (i + 0.5) / count
        c = ((x0 + t * (x1 - x0), (y0 + y1) / 2) if along_x
             else ((x0 + x1) / 2, y0 + t * (y1 - y0)))
        r, h = float(rng.uniform(0.1, 0.12)), float(rng.uniform(1.3, 1.6))
        piece.solids += [("furniture", cylinder(c, r, 0.0, h, 10), _colour(rng, CYLINDERS)),
                         ("furniture", cylinder(c, 0.04, h, h + 0.12, 6), (0.6, 0.6, 0.6))]
        piece.blocking.append(Capsule(c, c, r))
    return piece


def _box_pile(rng: np.random.Generator, rect: Rect) -> Piece:
    """A floor box on ``rect`` (0.15-0.6 m high), sometimes with one or two smaller ones
    stacked on it."""
    x0, y0, x1, y1 = rect
    z = float(rng.uniform(0.15, 0.6))
    piece = Piece(footprint=rect, blocking=[rect],
                  solids=[("boxes", box(rect, 0.0, z), _colour(rng, BOX_COLOURS))])
    for _ in range(int(rng.choice([0, 0, 1, 2]))):
        w, d = (x1 - x0) * float(rng.uniform(0.5, 0.95)), (y1 - y0) * float(rng.uniform(0.5, 0.95))
        cx = float(rng.uniform(x0 + w / 2, x1 - w / 2))
        cy = float(rng.uniform(y0 + d / 2, y1 - d / 2))
        x0, y0, x1, y1 = cx - w / 2, cy - d / 2, cx + w / 2, cy + d / 2
        top = z + float(rng.uniform(0.12, 0.45))
        piece.solids.append(("boxes", box((x0, y0, x1, y1), z, top), _colour(rng, BOX_COLOURS)))
        z = top
    return piece


def _along_walls(rng: np.random.Generator, bounds, height: float, lab: Furnishing,
                 style: dict) -> None:
    """Benches, fume hoods, shelving, fridges, cabinets, gas cylinders and boxes along
    every wall, close together, each kept where the floor stays joined; stools in front
    of some benches."""
    kinds = ("bench", "hood", "shelves", "fridge", "cabinet", "gas", "boxes")
    for side in range(4):
        length = wall_length(bounds, side)
        s = float(rng.uniform(0.0, 0.6))
        while s < length - 0.3:
            kind = kinds[int(rng.choice(len(kinds), p=[0.38, 0.08, 0.17, 0.08, 0.07, 0.06, 0.16]))]
            width, depth = {
                "bench": (rng.uniform(1.2, 3.0), rng.uniform(0.6, 0.75)),
                "hood": (rng.uniform(1.2, 1.8), rng.uniform(0.75, 0.9)),
                "shelves": (rng.uniform(0.9, 1.8), rng.uniform(0.4, 0.55)),
                "fridge": (rng.uniform(0.6, 0.8), rng.uniform(0.65, 0.75)),
                "cabinet": (rng.uniform(0.8, 1.2), rng.uniform(0.45, 0.6)),
                "gas": (rng.uniform(0.5, 1.0), 0.26),
                "boxes": (rng.uniform(0.25, 0.7), rng.uniform(0.25, 0.6))}[kind]
            width, depth = float(min(width, length - s - 0.03)), float(depth)
            if width < 0.25:
                break
            rect = against_wall(bounds, side, s + width / 2, width, depth)
            if kind == "bench":
                piece = _bench(rng, rect, side, float(rng.uniform(0.86, 0.95)), height, style)
            elif kind == "hood":
                piece = _fume_hood(rng, rect, side, height)
            elif kind == "shelves":
                piece = _shelves(rng, rect, style)
            elif kind == "gas":
                piece = _gas_cylinders(rng, rect)
            elif kind == "boxes":
                piece = _box_pile(rng, rect)
            else:
                piece = _tall_box(rng, rect, height, kind)
            if lab.place(piece):
                s += width
                if kind == "bench" and rng.random() < 0.3:
                    _stools_by(rng, rect, side, lab, style)
            s += float(rng.uniform(0.03, 0.5) if rng.random() < 0.75 else rng.uniform(0.6, 1.5))


def _tall_box(rng: np.random.Generator, rect: Rect, wall_height: float, kind: str) -> Piece:
    """A fridge (white or grey, 1.7-1.9 m) or a tall cabinet (tinted wood, concrete or
    paint, 1.8-2.2 m) on floor rectangle ``rect``."""
    if kind == "fridge":
        surface = {"color": shade(rng, (0.9, 0.9, 0.9) if rng.random() < 0.7
                                  else (0.6, 0.62, 0.64), 0.05) + (1.0,), "texture": None}
        height = float(rng.uniform(1.7, 1.9))
    else:
        surface = finish(rng, CASEWORK_TEXTURES, plain=0.5, low=0.45, high=0.9)
        height = float(rng.uniform(1.8, 2.2))
    return Piece(footprint=rect, blocking=[rect], landmarks=[
        box_landmark(rect, min(height, wall_height - 0.05), kind, **surface)])


def _stools_by(rng: np.random.Generator, rect: Rect, side: int | None, lab: Furnishing,
               style: dict) -> None:
    """One or two stools in front of the bench on ``rect`` (against wall ``side``; an
    island's on either long side when ``side`` is None)."""
    x0, y0, x1, y1 = rect
    along_x = x1 - x0 >= y1 - y0 if side is None else side % 2 == 0
    fronts = ({0: [1], 1: [-1], 2: [-1], 3: [1]}[side] if side is not None else [-1, 1])
    for _ in range(int(rng.integers(1, 3))):
        out = fronts[int(rng.integers(len(fronts)))]
        off = float(rng.uniform(0.25, 0.45))
        slide = float(rng.uniform(-0.5, 0.5))
        if along_x:
            c = ((x0 + x1) / 2 + slide * max(x1 - x0 - 0.4, 0.0),
                 (y1 + off) if out > 0 else (y0 - off))
        else:
            c = ((x1 + off) if out > 0 else (x0 - off),
                 (y0 + y1) / 2 + slide * max(y1 - y0 - 0.4, 0.0))
        lab.place(stool(c, float(rng.uniform(0.6, 0.75)), style["seat"], style["metal"]))


def _islands(rng: np.random.Generator, bounds, height: float, lab: Furnishing,
             style: dict) -> list[Rect]:
    """One to three island benches at free places in the middle, often with a reagent
    rack on top, and stools round them; their floor rectangles."""
    (xmin, ymin), (xmax, ymax) = bounds
    placed: list[Rect] = []
    wanted = int(rng.integers(1, 4))
    for _ in range(30):
        if len(placed) == wanted:
            break
        length, depth = float(rng.uniform(1.8, 3.6)), float(rng.uniform(1.2, 1.5))
        along_x = rng.random() < 0.5
        w, d = (length, depth) if along_x else (depth, length)
        if w > xmax - xmin - 2.0 or d > ymax - ymin - 2.0:
            continue
        cx = float(rng.uniform(xmin + 1.0 + w / 2, xmax - 1.0 - w / 2))
        cy = float(rng.uniform(ymin + 1.0 + d / 2, ymax - 1.0 - d / 2))
        rect = (cx - w / 2, cy - d / 2, cx + w / 2, cy + d / 2)
        top = float(rng.uniform(0.86, 0.95))
        piece = _bench(rng, rect, None, top, height, style)
        if rng.random() < 0.6:           # a reagent rack along the spine
            piece.solids += _rack(rng, rect, top, style)
        if lab.place(piece):
            placed.append(rect)
            _stools_by(rng, rect, None, lab, style)
    return placed


def _rack(rng: np.random.Generator, rect: Rect, z: float, style: dict) -> list:
    """A reagent rack on the spine of an island bench ``rect`` whose top is ``z`` metres
    up: posts at its ends, one or two boards, bottles on them."""
    x0, y0, x1, y1 = rect
    along_x = x1 - x0 >= y1 - y0
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    span = ((x0 + 0.1, cy - 0.12, x1 - 0.1, cy + 0.12) if along_x
            else (cx - 0.12, y0 + 0.1, cx + 0.12, y1 - 0.1))
    high = float(rng.uniform(0.5, 0.8))
    sx0, sy0, sx1, sy1 = span
    ends = ([(sx0, sy0, sx0 + 0.03, sy1), (sx1 - 0.03, sy0, sx1, sy1)] if along_x
            else [(sx0, sy0, sx1, sy0 + 0.03), (sx0, sy1 - 0.03, sx1, sy1)])
    solids = [("on_top", box(e, z, z + high), style["metal"]) for e in ends]
    for level in np.linspace(z + 0.3, z + high - 0.02, int(rng.integers(1, 3))):
        solids.append(("on_top", box(span, float(level), float(level) + 0.02), style["board"]))
        solids += _items_on(rng, span, float(level) + 0.02, int(rng.integers(2, 6)))
    return solids


def _floor_clutter(rng: np.random.Generator, bounds, lab: Furnishing, style: dict
                  ) -> list[Rect]:
    """Trolleys (boxes on their trays), stools and heaps of two to six floor boxes at
    free places, about 0.15-0.4 heaps a square metre tried; the floor rectangles of the
    boxes (or piles) placed."""
    (xmin, ymin), (xmax, ymax) = bounds

    def spot(half_w: float, half_d: float, near=None) -> Rect:
        """A rectangle of half sizes ``half_w`` x ``half_d`` anywhere on the floor, or
        within 0.6 m of the point ``near``."""
        x, y = ((rng.uniform(xmin, xmax), rng.uniform(ymin, ymax)) if near is None
                else (near[0] + rng.uniform(-0.6, 0.6), near[1] + rng.uniform(-0.6, 0.6)))
        x = float(np.clip(x, xmin + half_w + 0.03, xmax - half_w - 0.03))
        y = float(np.clip(y, ymin + half_d + 0.03, ymax - half_d - 0.03))
        return x - half_w, y - half_d, x + half_w, y + half_d

    for _ in range(int(rng.integers(1, 4))):
        w, d = float(rng.uniform(0.5, 0.9)), float(rng.uniform(0.4, 0.55))
        w, d = (d, w) if rng.random() < 0.5 else (w, d)
        for _ in range(10):
            rect = spot(w / 2, d / 2)
            piece = cart(rect, style["metal"], style["board"])
            for z in (0.18, 0.83):
                piece.solids += _items_on(rng, rect, z, int(rng.integers(0, 3)), bottles=0.2,
                                          palette=BOX_COLOURS)
            if lab.place(piece):
                break
    for _ in range(int(rng.integers(0, 4))):
        for _ in range(5):
            x0, y0, x1, y1 = spot(0.19, 0.19)
            if lab.place(stool(((x0 + x1) / 2, (y0 + y1) / 2), float(rng.uniform(0.6, 0.75)),
                               style["seat"], style["metal"])):
                break
    piles: list[Rect] = []
    for _ in range(int((xmax - xmin) * (ymax - ymin) * rng.uniform(0.15, 0.4))):
        centre = None
        for _ in range(int(rng.integers(2, 7))):
            rect = spot(float(rng.uniform(0.075, 0.35)), float(rng.uniform(0.075, 0.3)), centre)
            if lab.place(_box_pile(rng, rect)):
                piles.append(rect)
                centre = ((rect[0] + rect[2]) / 2, (rect[1] + rect[3]) / 2)
    return piles


def labs_scene(rng: np.random.Generator) -> Scene:
    """Draw a ``labs`` world from ``rng`` (see the module doc)."""
    horizon, appearance = random_appearance(rng, outdoor=False)
    width, depth = float(rng.uniform(6.0, 12.0)), float(rng.uniform(5.0, 9.0))
    bounds = ((-width / 2, -depth / 2), (width / 2, depth / 2))
    height, thickness = float(rng.uniform(2.0, 3.0)), float(rng.uniform(0.1, 0.25))
    paint = finish(rng, WALL_TEXTURES, plain=0.55, low=0.7, high=0.95, hue=0.05)
    walls = outer_walls(bounds, thickness, height, wall_finishes(
        rng, paint, 0.8, WALL_TEXTURES, plain=0.5, low=0.55, high=0.9, hue=0.1))
    floor = finish(rng, FLOOR_TEXTURES, plain=0.35, low=0.3, high=0.65, hue=0.06, tint=0.45)
    style = {
        "casework": finish(rng, CASEWORK_TEXTURES, plain=0.6, low=0.55, high=0.95, hue=0.12),
        "cupboard": finish(rng, CASEWORK_TEXTURES, plain=0.6, low=0.55, high=0.95, hue=0.12),
        "worktop": _colour(rng, WORKTOPS), "metal": shade(rng, (0.6, 0.61, 0.63), 0.15),
        "board": shade(rng, (0.7, 0.7, 0.7), 0.2), "seat": _colour(rng, BOX_COLOURS[2:8]),
    }
    lab = Furnishing(FloorPlan(bounds))
    window_sides = [int(k) for k in rng.permutation(4)[:int(rng.integers(0, 3))]]
    lab.landmarks += windows(rng, walls, window_sides, height)
    _along_walls(rng, bounds, height, lab, style)
    islands = _islands(rng, bounds, height, lab, style)
    boxes = _floor_clutter(rng, bounds, lab, style)
    lab.landmarks += wall_decor(rng, walls, skip=window_sides)
    return Scene(name="labs", bounds=bounds, walls=tuple(walls), landmarks=tuple(lab.landmarks),
                 floor_color=floor["color"], floor_texture=floor["texture"], meshes=lab.parts(),
                 sky_color=horizon, appearance=appearance,
                 metadata={"floor_boxes": boxes, "islands": islands})
