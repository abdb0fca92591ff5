"""``offices``: an open-plan office floor, new every episode (drawn from the episode's random
generator, so ``reset(seed=...)`` reproduces it).

A rectangular floor of 8-16 x 6-12 m inside walls 2-3 m high, painted in pale colours or
tinted textures (sometimes one accent wall); the floor is carpet, tiles or wood, tinted.
Bands of windows (sky-pale or striped-blind panels from 0.8-1.1 m up) run along one to
three outer walls. Up to two corners hold a meeting room (2.6-4 x 2.6-3.5 m) behind
interior walls with a door 0.9-1.2 m wide, a table with chairs round it and a whiteboard.
The open floor holds desks (1.2-1.6 x 0.7-0.8 m, 0.72-0.76 m high, each with a monitor
and mostly a swivel chair) in islands of two facing rows, often split by a partition
1.0-1.4 m high, or in rows facing one way; cabinets, lockers, bookcases, printers, water
coolers and plants stand along the walls and a few plants on the floor; posters,
pictures and whiteboards hang on the walls without windows and on the meeting rooms.

The robot bumps into walls, partitions and cabinets (landmarks) and into desks and tables
as a whole (their floor frame, :mod:`~homing_gym.scenes.families.indoor_parts`), the
five-armed feet of chairs, plant pots and coolers (mesh parts); it passes under crowns,
never touches monitors. A piece is kept only if every part of the floor stays reachable
through aisles at least 0.6 m wide (:class:`~homing_gym.scenes.families.indoor_parts.
FloorPlan`). Sizes, counts, layout, colours, textures and the world's appearance
(:func:`~homing_gym.scenes.appearance.random_appearance`, indoors) are drawn per world.
``scene.metadata`` holds ``meeting_rooms`` and ``desks`` (floor rectangles (xmin, ymin,
xmax, ymax) of the rooms and of the open floor's desk tops) and ``chairs`` (the floor
points of the open floor's chairs).
"""

from __future__ import annotations

import math

import numpy as np

from homing_gym.scenes.appearance import random_appearance
from homing_gym.scenes.base import Landmark, Scene, Wall
from homing_gym.scenes.families.indoor_parts import (
    Capsule, FloorPlan, Furnishing, Piece, Rect, against_wall, box, box_landmark, cylinder,
    decor, finish, grown, office_chair, outer_walls, potted_plant, shade, table, wall_decor,
    wall_finishes, wall_length, windows)

WALL_TEXTURES = ("concrete", "bricks_grey", "bricks_red", "wood_light", "stripes_cool",
                 "checker_green")
FLOOR_TEXTURES = ("concrete", "floor_tiles", "wood_light", "wood_dark", "checker_dark")
CABINET_TEXTURES = ("wood_light", "wood_dark", "concrete")
PARTITION_TEXTURES = ("concrete", "checker_dark", "stripes_cool", "wood_light")
#: Desk-top laminates, desk and chair metals and chair fabrics (RGB) a world picks from.
LAMINATES = ((0.92, 0.92, 0.9), (0.75, 0.75, 0.74), (0.8, 0.64, 0.45), (0.65, 0.48, 0.3),
             (0.36, 0.25, 0.17), (0.18, 0.18, 0.2))
METALS = ((0.72, 0.73, 0.75), (0.12, 0.12, 0.13), (0.9, 0.9, 0.9))
FABRICS = ((0.2, 0.2, 0.22), (0.08, 0.08, 0.1), (0.15, 0.25, 0.55), (0.6, 0.15, 0.12),
           (0.2, 0.45, 0.3), (0.85, 0.5, 0.15), (0.5, 0.5, 0.55))
INTERIOR_WALL = 0.1
DOOR_WIDTH = (0.9, 1.2)


def _pick(rng: np.random.Generator, choices) -> tuple[float, float, float]:
    """One of ``choices`` (RGB), shaded a little."""
    return shade(rng, choices[rng.integers(len(choices))], 0.06)


def _meeting_room(rng: np.random.Generator, corner: int, bounds, height: float,
                  room: Furnishing, style: dict, walls: list[Wall]) -> Rect | None:
    """A meeting room in ``corner`` (0-3: SW, SE, NE, NW) of ``bounds``: two interior walls
    with a door, then a table, chairs and a whiteboard; the room's floor rectangle, or
    None where it does not fit. Adds its walls to ``walls``."""
    (xmin, ymin), (xmax, ymax) = bounds
    sx, sy = ((-1, -1), (1, -1), (1, 1), (-1, 1))[corner]
    rw = float(rng.uniform(2.6, min(4.0, 0.4 * (xmax - xmin))))
    rd = float(rng.uniform(2.6, min(3.5, 0.5 * (ymax - ymin))))
    x_far = xmax if sx > 0 else xmin
    y_far = ymax if sy > 0 else ymin
    x_open, y_open = x_far - sx * rw, y_far - sy * rd
    rect = (min(x_far, x_open), min(y_far, y_open), max(x_far, x_open), max(y_far, y_open))
    t = INTERIOR_WALL
    if not room.plan.is_free(grown(rect, t + 0.8)):
        return None
    xw, yw = x_open - sx * t / 2, y_open - sy * t / 2       # the walls' centre lines
    style_wall = dict(height=height, thickness=t, **style["interior"])
    segments = [((xw, yw), (xw, y_far)), ((xw, yw), (x_far, yw))]
    doors = [k for k in range(2) if rng.random() < 0.25] or [int(rng.integers(2))]
    pieces: list[Wall] = []
    door_zones = []
    for k, (a, b) in enumerate(segments):
        if k not in doors:
            pieces.append(Wall(a, b, **style_wall))
            continue
        length = math.dist(a, b)
        width = float(rng.uniform(*DOOR_WIDTH))
        centre = float(rng.uniform(t + 0.3 + width / 2, length - 0.3 - width / 2))
        ux, uy = (b[0] - a[0]) / length, (b[1] - a[1]) / length
        at = lambda s: (a[0] + s * ux, a[1] + s * uy)  # noqa: E731
        pieces += [Wall(a, at(centre - width / 2), **style_wall),
                   Wall(at(centre + width / 2), b, **style_wall)]
        door_zones.append(_door_zone(at(centre), width, ux, uy))
    blocking = [_wall_rect(w) for w in pieces]
    if not room.place(Piece(footprint=None, blocking=blocking)):
        return None
    walls += pieces
    for zone in blocking + door_zones:
        room.plan.reserve(zone)
    _furnish_meeting_room(rng, rect, room, style)
    inner = [w for w in pieces if w.length > 1.4]
    if inner and rng.random() < 0.7:                # a whiteboard inside, or a poster outside
        wall = inner[int(rng.integers(len(inner)))]
        facing = 1.0 if _faces(wall, 1.0, rect) else -1.0
        room.landmarks += decor(rng, wall, facing if rng.random() < 0.6 else -facing, 0.0,
                                 wall.length, 1)
    room.plan.reserve(rect)
    return rect


def _door_zone(mid, width: float, ux: float, uy: float) -> Rect:
    """The floor kept clear on both sides of a door ``width`` metres wide centred on
    ``mid`` in a wall running along (``ux``, ``uy``)."""
    half_along, half_across = width / 2, 0.6
    hx = abs(ux) * half_along + abs(uy) * half_across
    hy = abs(uy) * half_along + abs(ux) * half_across
    return mid[0] - hx, mid[1] - hy, mid[0] + hx, mid[1] + hy


def _wall_rect(wall: Wall) -> Rect:
    """The floor rectangle an axis-aligned ``wall`` stands on."""
    (x0, y0), (x1, y1) = wall.start, wall.end
    return grown((min(x0, x1), min(y0, y1), max(x0, x1), max(y0, y1)), wall.thickness / 2)


def _faces(wall: Wall, side: float, rect: Rect) -> bool:
    """Whether the ``side`` face of ``wall`` looks into floor rectangle ``rect``."""
    (x0, y0), (x1, y1) = wall.start, wall.end
    nx, ny = -(y1 - y0) * side, (x1 - x0) * side
    cx, cy = (rect[0] + rect[2]) / 2, (rect[1] + rect[3]) / 2
    return (cx - x0) * nx + (cy - y0) * ny > 0


def _furnish_meeting_room(rng: np.random.Generator, rect: Rect, room: Furnishing,
                          style: dict) -> None:
    """A table along the room's long side, chairs round it, sometimes a plant."""
    x0, y0, x1, y1 = rect
    along_x = x1 - x0 >= y1 - y0
    long, short = (x1 - x0, y1 - y0) if along_x else (y1 - y0, x1 - x0)
    length = float(rng.uniform(1.2, max(1.2, min(3.0, long - 1.5))))
    width = float(rng.uniform(0.8, min(1.2, short - 1.6)))
    cx = (x0 + x1) / 2 + float(rng.uniform(-0.15, 0.15))
    cy = (y0 + y1) / 2 + float(rng.uniform(-0.15, 0.15))
    height, panel_ends = float(rng.uniform(0.72, 0.76)), bool(rng.random() < 0.4)
    for shrink in (1.0, 0.8, 0.6, 0.0):          # smaller where a door's way is kept clear
        if shrink == 0.0:
            return
        hx, hy = (length / 2, width / 2) if along_x else (width / 2, length / 2)
        hx, hy = hx * shrink, hy * shrink
        if room.place(table((cx - hx, cy - hy, cx + hx, cy + hy), height, style["table"],
                            style["frame"], panel_ends)):
            length, width = length * shrink, width * shrink
            break
    seats = max(1, int(length // 0.75))
    for i in range(seats):
        t = (i + 0.5) / seats * length - length / 2
        for side in (-1, 1):
            out = width / 2 + float(rng.uniform(0.2, 0.4))
            x, y = (cx + t, cy + side * out) if along_x else (cx + side * out, cy + t)
            yaw = math.atan2(-side, 0.0) if along_x else math.atan2(0.0, -side)
            room.place(office_chair((x, y), yaw + float(rng.uniform(-0.3, 0.3)),
                                    style["seat"], style["chair_metal"]))
    if rng.random() < 0.4:
        corner = (x0 + 0.35, y0 + 0.35) if rng.random() < 0.5 else (x1 - 0.35, y1 - 0.35)
        room.place(potted_plant(rng, corner))


def _island(rng: np.random.Generator, frame: "_Frame", u0: float, n: int, rows: tuple,
            partition: float | None, desk: tuple[float, float, float], style: dict
            ) -> tuple[Piece, list[Rect], list[tuple[float, float]]]:
    """Desks ``n`` abreast from ``u0`` in the layout ``frame`` (local (u, v) -> world) in
    ``rows`` ((v of the desks' back edge, +1 or -1: the side of their front and chair)),
    each with a monitor and mostly a chair, and a partition along v = ``partition``
    (or none); the piece, its desk tops' floor rectangles and its chairs' floor points."""
    w, d, h = desk
    piece = Piece(footprint=None)
    desks: list[Rect] = []
    chairs: list[tuple[float, float]] = []
    for back, out in rows:
        front = back + out * d
        for i in range(n):
            ua, ub = u0 + i * w, u0 + (i + 1) * w
            top = frame.rect(ua + 0.005, min(back, front), ub - 0.005, max(back, front))
            part = table(top, h, style["desk"], style["frame"], style["panel_ends"])
            desks.append(top)
            piece.blocking += part.blocking
            piece.solids += part.solids
            screen = 0.5 + 0.1 * rng.random()
            mu = (ua + ub) / 2 + float(rng.uniform(-0.2, 0.2))
            mv = back + out * 0.13
            piece.solids += [
                ("on_top", box(frame.rect(mu - 0.04, mv - 0.04, mu + 0.04, mv + 0.04), h,
                               h + 0.12), style["screen"]),
                ("on_top", box(frame.rect(mu - screen / 2, mv + out * 0.03 - 0.015,
                                          mu + screen / 2, mv + out * 0.03 + 0.015),
                               h + 0.1, h + 0.1 + screen * 0.6), style["screen"])]
            if rng.random() < 0.85:
                cu = (ua + ub) / 2 + float(rng.uniform(-0.15, 0.15))
                cv = front + out * float(rng.uniform(0.22, 0.45))
                chair = office_chair(frame.xy(cu, cv), frame.yaw(-out)
                                     + float(rng.uniform(-0.5, 0.5)), style["seat"],
                                     style["chair_metal"])
                piece.blocking += chair.blocking
                piece.solids += chair.solids
                chairs.append(frame.xy(cu, cv))
    if partition is not None:
        rect = frame.rect(u0, partition - 0.02, u0 + n * w, partition + 0.02)
        piece.blocking.append(rect)
        piece.landmarks.append(_partition(rect, style))
    return piece, desks, chairs


def _partition(rect: Rect, style: dict) -> Landmark:
    """A low partition standing on floor rectangle ``rect``."""
    return box_landmark(rect, style["partition_height"], "partition",
                        **style["partition_finish"])


class _Frame:
    """Local layout coordinates (u along the desk rows, v across) to world ones: the
    identity, or u along y and v along x."""

    def __init__(self, along_x: bool):
        self.along_x = along_x

    def xy(self, u: float, v: float) -> tuple[float, float]:
        return (u, v) if self.along_x else (v, u)

    def rect(self, u0: float, v0: float, u1: float, v1: float) -> Rect:
        return (u0, v0, u1, v1) if self.along_x else (v0, u0, v1, u1)

    def yaw(self, v_sign: float) -> float:
        """World yaw (radians) of the local direction ``v_sign`` * +v."""
        return math.atan2(v_sign, 0.0) if self.along_x else math.atan2(0.0, v_sign)


def _desks(rng: np.random.Generator, bounds, room: Furnishing, style: dict
           ) -> tuple[list[Rect], list[tuple[float, float]]]:
    """Desk islands (two rows back to back) or single rows in bands across the open
    floor, packed along each band (shorter where the full length does not fit), with
    aisles 0.8-1.8 m wide between and up to 1-1.6 m left along the walls; the desk tops'
    floor rectangles and the chairs' floor points."""
    (xmin, ymin), (xmax, ymax) = bounds
    width, depth = xmax - xmin, ymax - ymin
    frame = _Frame(bool(rng.random() < (0.7 if width >= depth else 0.3)))
    lu, lv = (width, depth) if frame.along_x else (depth, width)
    desk = (float(rng.uniform(1.2, 1.6)), float(rng.uniform(0.7, 0.8)),
            float(rng.uniform(0.72, 0.76)))
    w, d, _ = desk
    islands = rng.random() < 0.65
    n = int(rng.integers(2, 5) if islands else rng.integers(2, 7))
    chair_zone = float(rng.uniform(0.6, 0.8))
    gap = 0.05 if style["partition"] else 0.0
    span_v = (2 * d + gap + 2 * chair_zone) if islands else (d + gap + chair_zone)
    aisle_u, aisle_v = float(rng.uniform(0.9, 1.8)), float(rng.uniform(0.8, 1.5))
    margin = min(float(rng.uniform(1.0, 1.6)), (lv - span_v) / 2)     # room for a row
    room_u, room_v = lu - 2 * margin, lv - 2 * margin
    count_v = max(0, int((room_v + aisle_v) // (span_v + aisle_v)))
    left_v = room_v - count_v * (span_v + aisle_v) + aisle_v
    out = 1.0 if rng.random() < 0.5 else -1.0          # the side of the rows' chairs
    desks: list[Rect] = []
    chairs: list[tuple[float, float]] = []
    for iv in range(count_v):
        v0 = (-lv / 2 + margin + left_v / 2 + iv * (span_v + aisle_v)
              + float(rng.uniform(-0.1, 0.1)))
        if islands:
            spine = v0 + chair_zone + d + gap / 2
            rows = ((spine - gap / 2, -1.0), (spine + gap / 2, 1.0))
        else:
            back = v0 + gap if out > 0 else v0 + chair_zone + d
            rows, spine = ((back, out),), back - out * gap / 2
        u = -lu / 2 + margin + float(rng.uniform(0.0, max(0.0, room_u % (n * w + aisle_u))))
        while u + w <= lu / 2 - margin:     # islands packed along u, shorter where needed
            step = 0.4
            for k in range(n, 0, -1) if rng.random() > 0.08 else ():
                if u + k * w > lu / 2 - margin:
                    continue
                piece, tops, seats = _island(rng, frame, u, k, rows,
                                               spine if style["partition"] else None, desk,
                                               style)
                piece.footprint = frame.rect(u, v0, u + k * w, v0 + span_v)
                if room.place(piece):
                    desks, chairs, step = desks + tops, chairs + seats, k * w + aisle_u
                    break
            u += step
    return desks, chairs


def _along_walls(rng: np.random.Generator, bounds, height: float, room: Furnishing) -> None:
    """Cabinets, lockers, bookcases, printers, water coolers and plants along the walls,
    with gaps, each kept where the floor stays joined."""
    for side in range(4):
        length = wall_length(bounds, side)
        s = float(rng.uniform(0.1, 1.0))
        while s < length - 0.4:
            kind = rng.choice(["cabinet", "locker", "bookcase", "printer", "cooler", "plant"],
                              p=[0.3, 0.15, 0.2, 0.1, 0.08, 0.17])
            if kind in ("cooler", "plant"):
                size = 0.42
                rect = against_wall(bounds, side, s + size / 2, size, size)
                centre = ((rect[0] + rect[2]) / 2, (rect[1] + rect[3]) / 2)
                piece = (potted_plant(rng, centre) if kind == "plant"
                         else _cooler(rng, centre))
            else:
                width = float(rng.uniform(*{"cabinet": (0.8, 1.8), "locker": (0.8, 1.2),
                                            "bookcase": (0.7, 1.2), "printer": (0.5, 0.7)}[kind]))
                dep = float(rng.uniform(*{"cabinet": (0.4, 0.5), "locker": (0.45, 0.55),
                                          "bookcase": (0.3, 0.38), "printer": (0.5, 0.65)}[kind]))
                top = {"cabinet": (0.7, 1.1), "locker": (1.8, min(2.1, height - 0.1)),
                       "bookcase": (1.2, min(2.0, height - 0.1)), "printer": (0.9, 1.2)}[kind]
                rect = against_wall(bounds, side, s + width / 2, width, dep)
                piece = Piece(footprint=rect, blocking=[rect], landmarks=[
                    _cabinet(rng, rect, float(rng.uniform(*top)), kind)])
            run = (rect[2] - rect[0]) if side % 2 == 0 else (rect[3] - rect[1])
            if s + run > length - 0.03:
                break
            if room.place(piece):
                s += run
            s += float(rng.uniform(0.05, 1.5) if rng.random() < 0.6 else rng.uniform(1.5, 3.0))


def _cabinet(rng: np.random.Generator, rect: Rect, height: float, kind: str) -> Landmark:
    """A box landmark on floor rectangle ``rect``: a cabinet or locker (wood,
    concrete-grey or plain paint), a bookcase (striped spines or dark wood) or a printer
    (pale grey)."""
    if kind == "bookcase":
        surface = {"color": tuple(float(c) for c in rng.uniform(0.6, 1.0, 3)) + (1.0,),
                   "texture": "stripes_warm" if rng.random() < 0.7 else "wood_dark"}
    elif kind == "printer":
        surface = {"color": shade(rng, (0.78, 0.78, 0.8), 0.08) + (1.0,), "texture": None}
    else:
        surface = finish(rng, CABINET_TEXTURES, plain=0.5, low=0.45, high=0.95, hue=0.06)
    return box_landmark(rect, height, kind, **surface)


def _cooler(rng: np.random.Generator, centre) -> Piece:
    """A water cooler: a pale body 1.0-1.1 m high and a blue bottle on it."""
    h = float(rng.uniform(1.0, 1.1))
    return Piece(footprint=(centre[0] - 0.2, centre[1] - 0.2, centre[0] + 0.2, centre[1] + 0.2),
                 blocking=[Capsule(tuple(centre), tuple(centre), 0.17)],
                 solids=[("furniture", cylinder(centre, 0.17, 0.0, h), shade(rng, (0.88,) * 3)),
                         ("furniture", cylinder(centre, 0.13, h, h + 0.4),
                          shade(rng, (0.45, 0.65, 0.9)))])


def offices_scene(rng: np.random.Generator) -> Scene:
    """Draw an ``offices`` world from ``rng`` (see the module doc)."""
    horizon, appearance = random_appearance(rng, outdoor=False)
    width, depth = float(rng.uniform(8.0, 16.0)), float(rng.uniform(6.0, 12.0))
    bounds = ((-width / 2, -depth / 2), (width / 2, depth / 2))
    height, thickness = float(rng.uniform(2.0, 3.0)), float(rng.uniform(0.1, 0.25))
    paint = finish(rng, WALL_TEXTURES, plain=0.6, low=0.75, high=0.95)
    walls = outer_walls(bounds, thickness, height, wall_finishes(
        rng, paint, 0.75, WALL_TEXTURES, plain=0.4, low=0.5, high=0.9, hue=0.15))
    floor = finish(rng, FLOOR_TEXTURES, plain=0.3, low=0.3, high=0.6, hue=0.08, tint=0.45)
    style = {
        "desk": _pick(rng, LAMINATES), "table": _pick(rng, LAMINATES),
        "frame": _pick(rng, METALS), "chair_metal": _pick(rng, METALS[:2]),
        "seat": _pick(rng, FABRICS), "screen": shade(rng, (0.08, 0.08, 0.1), 0.04),
        "panel_ends": bool(rng.random() < 0.4), "partition": bool(rng.random() < 0.6),
        "partition_height": float(rng.uniform(1.0, 1.4)),
        "partition_finish": finish(rng, PARTITION_TEXTURES, plain=0.5, low=0.4, high=0.8,
                                   hue=0.1, tint=0.5),
        "interior": finish(rng, WALL_TEXTURES, plain=0.6, low=0.6, high=0.95, hue=0.1),
    }
    window_sides = [int(s) for s in rng.permutation(4)[:int(rng.integers(1, 4))]]
    room = Furnishing(FloorPlan(bounds))
    room.landmarks += windows(rng, walls, window_sides, height)
    meeting_rooms = []
    for corner in rng.permutation(4)[:int(rng.choice([0, 1, 1, 2]))]:
        if (rect := _meeting_room(rng, int(corner), bounds, height, room, style, walls)):
            meeting_rooms.append(rect)
    desks, chairs = _desks(rng, bounds, room, style)
    _along_walls(rng, bounds, height, room)
    for _ in range(int(rng.integers(0, 4))):            # plants standing free
        centre = rng.uniform(bounds[0], bounds[1])
        room.place(potted_plant(rng, (float(centre[0]), float(centre[1]))))
    room.landmarks += wall_decor(rng, walls, skip=window_sides)
    return Scene(name="offices", bounds=bounds, walls=tuple(walls),
                 landmarks=tuple(room.landmarks), floor_color=floor["color"],
                 floor_texture=floor["texture"], meshes=room.parts(), sky_color=horizon,
                 appearance=appearance,
                 metadata={"meeting_rooms": meeting_rooms, "desks": desks, "chairs": chairs})
