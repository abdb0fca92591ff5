"""Building blocks of the indoor world families (:mod:`~homing_gym.scenes.families.offices`,
:mod:`~homing_gym.scenes.families.labs`): a floor plan that accepts a piece of furniture
only where every part of the floor stays reachable through aisles (:class:`FloorPlan`),
closed solids for mesh furniture (boxes, prisms, rectangular rings), furniture pieces
(:class:`Piece`: desks and tables, chairs, stools, shelving, carts, plants) and
wall-mounted panels. Units: metres, z up, the floor at z = 0; colours RGB(A) in [0, 1].

Tables, desks, stools and shelving stand on a low closed ring (a floor frame, a foot
rail, a bottom shelf) inside the robot's height band: the footprint of a closed solid is
filled whole (:mod:`homing_gym.scenes.footprint`), so the floor under them is blocked as
a whole and no unreachable pocket opens between their legs and the chairs around them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from scipy import ndimage

from homing_gym.scenes.base import Landmark, Wall
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.random_nature import _lump, _part

Mesh = tuple[np.ndarray, np.ndarray]
#: A floor rectangle (xmin, ymin, xmax, ymax), metres.
Rect = tuple[float, float, float, float]
RGB = tuple[float, float, float]

#: The clearance (metres) the local homing task keeps around a home and start, and the
#: disc its paths are planned for: no free pocket that holds it may be cut off.
ROBOT_CLEARANCE = 0.22
#: Least width (metres) of the aisles that join every part of the floor.
AISLE = 0.6
#: Spacing (metres) of the floor plan's grid: that of the task's paths
#: (:data:`homing_gym.paths.RESOLUTION`).
CELL = 0.05
#: Textures of posters and pictures (tinted).
POSTER_TEXTURES = ("poster_a", "poster_b", "stripes_warm", "stripes_cool", "checker_green",
                   "bricks_red", "wood_light")
#: Neighbours that join grid points into regions (as :func:`homing_gym.paths.regions`).
_EIGHT = np.ones((3, 3), bool)
#: How far (metres) the panels hung on a wall (:func:`wall_panel`) stand off it, and the
#: gap left between a wall and the furniture against it.
PANEL_DEPTH, OFF_WALL = 0.021, 0.03
#: How far (metres) the clearances the task sees may differ from the floor plan's: the
#: footprints are rasterised in 2 cm cells (:mod:`homing_gym.scenes.footprint`) and
#: round things are polygons inside the plan's discs.
MARGIN = 0.03
#: The clearances (metres) at which the floor plan must stay one region: every one
#: within :data:`MARGIN` of :data:`ROBOT_CLEARANCE` (2 cm apart), so that no narrow way
#: into a pocket or along a closed channel is left whose width the plan may misjudge;
#: and :data:`AISLE` / 2 + :data:`MARGIN`, the one most pieces fail at, first.
_RADII = (AISLE / 2 + MARGIN,
          *np.arange(ROBOT_CLEARANCE + MARGIN, ROBOT_CLEARANCE - MARGIN - 0.005, -0.02))


def grown(rect: Rect, margin: float) -> Rect:
    """``rect`` widened by ``margin`` metres on every side (narrowed if negative)."""
    x0, y0, x1, y1 = rect
    return x0 - margin, y0 - margin, x1 + margin, y1 + margin


def square(centre, half: float) -> Rect:
    """The square of half side ``half`` metres around floor point ``centre``."""
    return centre[0] - half, centre[1] - half, centre[0] + half, centre[1] + half


@dataclass(frozen=True)
class Capsule:
    """A floor segment from ``a`` to ``b`` widened by ``radius`` metres (a disc when
    ``a == b``): the arm of a chair's foot, a pot."""

    a: tuple[float, float]
    b: tuple[float, float]
    radius: float

    @property
    def rect(self) -> Rect:
        """Its bounding rectangle."""
        return grown((min(self.a[0], self.b[0]), min(self.a[1], self.b[1]),
                      max(self.a[0], self.b[0]), max(self.a[1], self.b[1])), self.radius)

    def distance(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Distance (metres) from floor points (``x``, ``y``) to it; 0 inside."""
        dx, dy = self.b[0] - self.a[0], self.b[1] - self.a[1]
        px, py = x - self.a[0], y - self.a[1]
        t = np.clip((px * dx + py * dy) / max(dx * dx + dy * dy, 1e-12), 0.0, 1.0)
        return np.maximum(np.hypot(px - t * dx, py - t * dy) - self.radius, 0.0)


def _distance(shape: "Rect | Capsule", x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Distance (metres) from floor points (``x``, ``y``) to a rectangle or capsule."""
    if isinstance(shape, Capsule):
        return shape.distance(x, y)
    x0, y0, x1, y1 = shape
    return np.hypot(np.maximum(np.maximum(x0 - x, x - x1), 0.0),
                    np.maximum(np.maximum(y0 - y, y - y1), 0.0))


class FloorPlan:
    """The floor ``bounds`` while furniture is placed: which cells footprints have taken,
    and the clearance of every point of the :data:`CELL` grid that the local homing task
    and its paths use (:func:`homing_gym.paths.occupancy`) to the bounds and the blocking
    shapes (rectangles and :class:`Capsule` s; the walls with their panels). :meth:`place`
    accepts a piece only on untaken floor and only if, with it, the points where a disc of
    :data:`ROBOT_CLEARANCE` fits and those where one of :data:`AISLE` fits each make one
    region (8-connected, as the paths join them), for every clearance in :data:`_RADII`:
    no pocket the task could start in is cut off, and every part is reached through
    aisles at least :data:`AISLE` wide."""

    def __init__(self, bounds):
        (self.x0, self.y0), (x1, y1) = bounds
        self.x = self.x0 + np.arange(int(math.floor((x1 - self.x0) / CELL)) + 1) * CELL
        self.y = self.y0 + np.arange(int(math.floor((y1 - self.y0) / CELL)) + 1) * CELL
        self.taken = np.zeros((len(self.x), len(self.y)), bool)
        self.clearance = np.minimum(
            np.minimum(self.x - self.x0, x1 - self.x)[:, None],
            np.minimum(self.y - self.y0, y1 - self.y)[None, :]) - PANEL_DEPTH

    def _cells(self, rect: Rect) -> tuple[slice, slice]:
        """The grid points in ``rect`` (and those within a cell of it)."""
        x0, y0, x1, y1 = rect
        return (slice(max(math.floor((x0 - self.x0) / CELL), 0),
                      max(math.ceil((x1 - self.x0) / CELL) + 1, 0)),
                slice(max(math.floor((y0 - self.y0) / CELL), 0),
                      max(math.ceil((y1 - self.y0) / CELL) + 1, 0)))

    def is_free(self, rect: Rect) -> bool:
        """Whether no footprint taken so far meets ``rect``."""
        return not self.taken[self._cells(rect)].any()

    def reserve(self, rect: Rect) -> None:
        """Take ``rect`` (nothing is placed there later; it still joins the floor)."""
        self.taken[self._cells(rect)] = True

    def place(self, footprint: Rect | None, blocking: "list[Rect | Capsule]") -> bool:
        """Take ``footprint`` and block ``blocking``, if the footprint is free and the
        floor stays joined; otherwise change nothing and return False."""
        if footprint is not None and not self.is_free(footprint):
            return False
        if blocking:
            rects = np.array([shape.rect if isinstance(shape, Capsule) else shape
                              for shape in blocking])
            window = self._cells(grown((*rects[:, :2].min(axis=0), *rects[:, 2:].max(axis=0)),
                                       max(_RADII) + 2 * CELL))
            x, y = self.x[window[0]][:, None], self.y[window[1]][None, :]
            old = self.clearance[window]
            new = np.minimum.reduce([old] + [_distance(shape, x, y) for shape in blocking])
            if not all(self._joined(window, old, new, radius) for radius in _RADII):
                return False
            self.clearance[window] = new
        if footprint is not None:
            self.reserve(footprint)
        return True

    def _joined(self, window: tuple[slice, slice], old: np.ndarray, new: np.ndarray,
                radius: float) -> bool:
        """Whether the grid points with clearance of at least ``radius`` stay one region
        when the clearances ``old`` in ``window`` become ``new``. They were one region:
        if the free points next to those lost are joined round them nearby, every way
        through the lost ones can go round; only otherwise is the whole floor labelled."""
        lost = (new < radius) & (old >= radius)
        if not lost.any():
            return True
        ii, jj = np.nonzero(lost)
        near = (slice(max(ii.min() - 3, 0), ii.max() + 4),
                slice(max(jj.min() - 3, 0), jj.max() + 4))
        free = new[near] >= radius
        labels = ndimage.label(free, structure=_EIGHT)[0]
        beside = labels[ndimage.binary_dilation(lost[near], structure=_EIGHT) & free]
        if beside.size and np.all(beside == beside[0]):
            return True
        floor = self.clearance.copy()
        floor[window] = new
        return ndimage.label(floor >= radius, structure=_EIGHT)[1] == 1


@dataclass
class Piece:
    """A piece of furniture before it is placed: the floor it takes (``footprint``;
    nothing else is put there), where it blocks the robot (``blocking``), its mesh
    ``solids`` ((part name, (vertices, faces), RGB) each) and its ``landmarks``."""

    footprint: Rect | None
    blocking: list[Rect | Capsule] = field(default_factory=list)
    solids: list[tuple[str, Mesh, RGB]] = field(default_factory=list)
    landmarks: list[Landmark] = field(default_factory=list)


class Furnishing:
    """A world's furniture as it is placed on a :class:`FloorPlan`: the accepted pieces'
    solids, gathered per mesh part, and landmarks."""

    #: Mesh parts and whether the robot bumps into them (the others stand above its
    #: height band: monitors, things on benches).
    COLLIDING = {"furniture": True, "plants": True, "boxes": True, "on_top": False}

    def __init__(self, plan: FloorPlan):
        self.plan = plan
        self.landmarks: list[Landmark] = []
        self._solids: dict[str, tuple[list[Mesh], list[RGB]]] = {
            name: ([], []) for name in self.COLLIDING}

    def place(self, piece: Piece) -> bool:
        """Add ``piece`` if the plan accepts it (:meth:`FloorPlan.place`)."""
        if not self.plan.place(piece.footprint, piece.blocking):
            return False
        for name, mesh, rgb in piece.solids:
            meshes, colors = self._solids[name]
            meshes.append(mesh)
            colors.append(np.clip(np.asarray(rgb, np.float64), 0, 1))
        self.landmarks += piece.landmarks
        return True

    def parts(self) -> tuple[MeshPart, ...]:
        """The gathered solids, one :class:`MeshPart` per part name that has any."""
        return tuple(_part(meshes, colors, name, self.COLLIDING[name])
                     for name, (meshes, colors) in self._solids.items() if meshes)


@lru_cache(maxsize=None)
def _prism_faces(n: int, fan_from_centre: bool) -> np.ndarray:
    """The faces of :func:`prism` over ``n`` corners (made once per kind; read-only)."""
    k = np.arange(n)
    k1 = (k + 1) % n
    faces = [np.column_stack([k, k1, n + k1]), np.column_stack([k, n + k1, n + k])]
    if fan_from_centre:
        faces += [np.column_stack([np.full(n, 2 * n + 1), n + k, n + k1]),
                  np.column_stack([np.full(n, 2 * n), k1, k])]
    else:
        j = np.arange(1, n - 1)
        faces += [np.column_stack([np.full(n - 2, n), n + j, n + j + 1]),
                  np.column_stack([np.zeros(n - 2, int), j + 1, j])]
    faces = np.concatenate(faces)
    faces.flags.writeable = False
    return faces


def prism(polygon, z0: float, z1: float, fan_from_centre: bool = False) -> Mesh:
    """A closed upright prism ``(vertices, faces)`` wound outwards over the floor polygon
    ``polygon`` (``(n, 2)`` metres, counter-clockwise) from height ``z0`` to ``z1``; its
    caps fan from the first corner (a convex polygon) or from the centroid
    (``fan_from_centre``: a star-shaped one)."""
    p = np.asarray(polygon, np.float64)
    n = len(p)
    vertices = np.empty((2 * n + 2 * fan_from_centre, 3))
    vertices[:n, :2], vertices[n:2 * n, :2] = p, p
    vertices[:n, 2], vertices[n:2 * n, 2] = z0, z1
    if fan_from_centre:
        vertices[2 * n:, :2] = p.mean(axis=0)
        vertices[2 * n:, 2] = z0, z1
    return vertices, _prism_faces(n, fan_from_centre)


def box(rect: Rect, z0: float, z1: float) -> Mesh:
    """An axis-aligned closed box over the floor rectangle ``rect`` from ``z0`` to ``z1``."""
    x0, y0, x1, y1 = rect
    return prism([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], z0, z1)


def turned_box(centre, length: float, width: float, yaw: float, z0: float,
               z1: float) -> Mesh:
    """A closed box ``length`` (along ``yaw``, radians) by ``width`` metres centred on
    floor point ``centre``, from ``z0`` to ``z1``."""
    c, s = math.cos(yaw), math.sin(yaw)
    local = np.array([(-1, -1), (1, -1), (1, 1), (-1, 1)]) * (length / 2, width / 2)
    return prism(local @ np.array([[c, s], [-s, c]]) + centre, z0, z1)


def cylinder(centre, radius: float, z0: float, z1: float, sides: int = 8) -> Mesh:
    """A closed upright ``sides``-sided prism of circumradius ``radius`` around
    ``centre`` from ``z0`` to ``z1``."""
    a = np.arange(sides) * 2 * math.pi / sides
    return prism(np.column_stack([np.cos(a), np.sin(a)]) * radius + centre, z0, z1)


def ring(rect: Rect, width: float, z0: float, z1: float) -> Mesh:
    """A closed rectangular ring (a frame ``width`` metres wide whose outer edge is
    ``rect``) from ``z0`` to ``z1``, wound outwards: one solid, so the floor it
    encloses counts as blocked."""
    x0, y0, x1, y1 = rect
    outer = np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], np.float64)
    inner = outer + np.array([(1, 1), (-1, 1), (-1, -1), (1, -1)]) * width
    vertices = np.concatenate([np.column_stack([corners, np.full(4, z)])
                               for corners in (outer, inner) for z in (z0, z1)])
    k = np.arange(4)
    k1 = (k + 1) % 4
    ob, ot, ib, it = k, 4 + k, 8 + k, 12 + k
    ob1, ot1, ib1, it1 = k1, 4 + k1, 8 + k1, 12 + k1
    faces = np.concatenate([np.column_stack(f) for f in (
        (ob, ob1, ot1), (ob, ot1, ot),          # outside
        (ib, it1, ib1), (ib, it, it1),          # inside, facing the hole
        (ot, ot1, it1), (ot, it1, it),          # top
        (ob, ib1, ob1), (ob, ib, ib1))])        # bottom
    return vertices, faces


def table(rect: Rect, height: float, top: RGB, frame: RGB, panel_ends: bool = False,
          shelf: float | None = None) -> Piece:
    """A desk or table over ``rect``, ``height`` metres high: a 3 cm top, four legs (or,
    with ``panel_ends``, a panel across each short end) on a floor frame ring, and
    optionally a lower shelf ``shelf`` metres up. It blocks the robot over its whole
    footprint."""
    base = grown(rect, -0.03)
    x0, y0, x1, y1 = base
    solids = [("furniture", box(rect, height - 0.03, height), top),
              ("furniture", ring(base, 0.04, 0.0, 0.06), frame)]
    if panel_ends and x1 - x0 >= y1 - y0:
        legs = [(x0, y0, x0 + 0.03, y1), (x1 - 0.03, y0, x1, y1)]
    elif panel_ends:
        legs = [(x0, y0, x1, y0 + 0.03), (x0, y1 - 0.03, x1, y1)]
    else:
        legs = [square((x, y), 0.025) for x in (x0 + 0.025, x1 - 0.025)
                for y in (y0 + 0.025, y1 - 0.025)]
    solids += [("furniture", box(leg, 0.06, height - 0.03), frame) for leg in legs]
    if shelf is not None:
        solids.append(("furniture", box(grown(base, -0.01), shelf, shelf + 0.02), top))
    return Piece(footprint=rect, blocking=[base], solids=solids)


def office_chair(centre, yaw: float, seat: RGB, metal: RGB) -> Piece:
    """A swivel chair at floor point ``centre`` facing ``yaw`` (radians): a five-armed
    foot 0.3 m in radius (the part the robot bumps into), a column, a round seat
    0.42-0.49 m up (0.24 m in radius, within the foot, so a camera never ends inside it)
    and a backrest from 0.55 m."""
    a = yaw + np.arange(10) * math.pi / 5
    r = np.where(np.arange(10) % 2 == 0, 0.3, 0.05)
    star = np.column_stack([r * np.cos(a), r * np.sin(a)]) + centre
    back = (centre[0] - 0.21 * math.cos(yaw), centre[1] - 0.21 * math.sin(yaw))
    solids = [("furniture", prism(star, 0.03, 0.08, fan_from_centre=True), metal),
              ("furniture", cylinder(centre, 0.03, 0.08, 0.42, sides=6), metal),
              ("furniture", cylinder(centre, 0.24, 0.42, 0.49), seat),
              ("furniture", turned_box(back, 0.05, 0.42, yaw, 0.55, 0.95), seat)]
    centre = (float(centre[0]), float(centre[1]))
    arms = [Capsule(centre, (float(x), float(y)), 0.02) for x, y in star[::2]]
    return Piece(footprint=square(centre, 0.3), blocking=[Capsule(centre, centre, 0.05), *arms],
                 solids=solids)


def stool(centre, height: float, seat: RGB, metal: RGB) -> Piece:
    """A lab stool at floor point ``centre``: a round seat ``height`` metres up on four
    legs joined by a foot rail ring 0.2-0.26 m up, 0.19 m from the centre."""
    rect = square(centre, 0.19)
    x0, y0, x1, y1 = rect
    solids = [("furniture", cylinder(centre, 0.18, height - 0.04, height), seat),
              ("furniture", ring(rect, 0.025, 0.2, 0.26), metal)]
    solids += [("furniture", box(square((x, y), 0.015), 0.0, height - 0.04), metal)
               for x in (x0 + 0.015, x1 - 0.015) for y in (y0 + 0.015, y1 - 0.015)]
    return Piece(footprint=rect, blocking=[rect], solids=solids)


def shelving(rect: Rect, height: float, boards: int, metal: RGB, board: RGB) -> Piece:
    """An open shelving unit over ``rect``: four corner posts ``height`` metres high and
    ``boards`` boards, the lowest 0.08 m up (a closed solid in the robot's band, so the
    whole unit blocks). ``Piece.solids[-boards:]`` are the boards, lowest first."""
    x0, y0, x1, y1 = rect
    posts = [square((x, y), 0.015) for x in (x0 + 0.015, x1 - 0.015)
             for y in (y0 + 0.015, y1 - 0.015)]
    solids = [("furniture", box(p, 0.0, height), metal) for p in posts]
    levels = np.linspace(0.08, height - 0.05, boards)
    solids += [("furniture", box(rect, z, z + 0.025), board) for z in levels]
    return Piece(footprint=rect, blocking=[rect], solids=solids)


def cart(rect: Rect, metal: RGB, tray: RGB) -> Piece:
    """A trolley over ``rect``: trays 0.15 m (in the robot's band: it blocks whole) and
    0.8 m up on four posts, and a push handle at 0.95 m along its x0 end."""
    x0, y0, x1, y1 = rect
    posts = [square((x, y), 0.015) for x in (x0 + 0.02, x1 - 0.02) for y in (y0 + 0.02, y1 - 0.02)]
    solids = [("furniture", box(p, 0.03, 0.95), metal) for p in posts]
    solids += [("furniture", box(rect, z, z + 0.03), tray) for z in (0.15, 0.8)]
    solids.append(("furniture", box((x0 + 0.005, y0 + 0.02, x0 + 0.035, y1 - 0.02), 0.92, 0.96),
                   metal))
    return Piece(footprint=rect, blocking=[rect], solids=solids)


def potted_plant(rng: np.random.Generator, centre) -> Piece:
    """A plant at floor point ``centre``: a pot (0.12-0.2 m in radius, 0.25-0.45 m high,
    what the robot bumps into), a stem and a leafy crown 0.4-1.1 m across from 0.62 m up,
    above any camera, in its own greens."""
    r, h = float(rng.uniform(0.12, 0.2)), float(rng.uniform(0.25, 0.45))
    crown_r, crown_h = float(rng.uniform(0.2, 0.55)), float(rng.uniform(0.25, 0.6))
    crown_v, crown_f = _lump(rng, centre, (crown_r, crown_r, crown_h))
    crown_v = crown_v + (0.0, 0.0, 0.62 - crown_v[:, 2].min())
    pot = np.array([rng.uniform(0.3, 0.9), rng.uniform(0.25, 0.8), rng.uniform(0.2, 0.75)])
    leaves = np.array([rng.uniform(0.08, 0.3), rng.uniform(0.35, 0.65), rng.uniform(0.05, 0.25)])
    solids = [("plants", cylinder(centre, r, 0.0, h), pot),
              ("plants", cylinder(centre, 0.025, h, 0.7, sides=5), (0.35, 0.27, 0.18)),
              ("plants", (crown_v, crown_f), leaves)]
    return Piece(footprint=square(centre, max(r, 0.15)),
                 blocking=[Capsule(tuple(centre), tuple(centre), r)], solids=solids)


def box_landmark(rect: Rect, height: float, name: str, color, texture: str | None = None,
                 base: float = 0.0) -> Landmark:
    """A box landmark over the floor rectangle ``rect``, ``height`` metres high from
    ``base`` metres up, turned along its longer side."""
    x0, y0, x1, y1 = rect
    along_x = x1 - x0 >= y1 - y0
    return Landmark(position=((x0 + x1) / 2, (y0 + y1) / 2), shape="box",
                    extent=(x1 - x0, y1 - y0) if along_x else (y1 - y0, x1 - x0),
                    yaw=0.0 if along_x else math.pi / 2, height=height, base=base,
                    color=tuple(color), texture=texture, name=name)


def against_wall(bounds, side: int, s: float, width: float, depth: float) -> Rect:
    """The floor rectangle ``width`` along and ``depth`` metres out from wall ``side``
    (0 south, 1 east, 2 north, 3 west of ``bounds``, counter-clockwise), its middle ``s``
    metres from the wall's counter-clockwise start corner, :data:`OFF_WALL` off the wall
    (clear of the panels hung on it)."""
    (xmin, ymin), (xmax, ymax) = bounds
    a, b, g = s - width / 2, s + width / 2, OFF_WALL
    if side == 0:
        return xmin + a, ymin + g, xmin + b, ymin + g + depth
    if side == 1:
        return xmax - g - depth, ymin + a, xmax - g, ymin + b
    if side == 2:
        return xmax - b, ymax - g - depth, xmax - a, ymax - g
    return xmin + g, ymax - b, xmin + g + depth, ymax - a


def wall_length(bounds, side: int) -> float:
    """Inner length (metres) of wall ``side`` of ``bounds`` (see :func:`against_wall`)."""
    (xmin, ymin), (xmax, ymax) = bounds
    return xmax - xmin if side % 2 == 0 else ymax - ymin


def outer_walls(bounds, thickness: float, height: float, finishes: list[dict]) -> list[Wall]:
    """The four walls whose inner faces are the edges of ``bounds``, counter-clockwise
    from the south wall (their left face, side +1, looks in), each with its finish
    (``color`` and ``texture``)."""
    (xmin, ymin), (xmax, ymax) = bounds
    t = thickness / 2
    corners = [(xmin - t, ymin - t), (xmax + t, ymin - t), (xmax + t, ymax + t),
               (xmin - t, ymax + t)]
    return [Wall(corners[k], corners[(k + 1) % 4], height=height, thickness=thickness,
                 **finishes[k]) for k in range(4)]


def wall_finishes(rng: np.random.Generator, paint: dict, keep: float,
                  textures: tuple[str, ...], **other) -> list[dict]:
    """Finishes of the four outer walls (for :func:`outer_walls`): each the room's
    ``paint`` with probability ``keep``, otherwise a :func:`finish` of its own from
    ``textures`` (``other``: its other arguments)."""
    return [paint if rng.random() < keep else finish(rng, textures, **other) for _ in range(4)]


def wall_panel(wall: Wall, side: float, s: float, width: float, height: float, base: float,
               color, texture: str | None, name: str) -> Landmark:
    """A panel (window, poster, board) ``width`` x ``height`` metres, ``base`` metres up,
    on the ``side`` face (+1: left of start->end) of ``wall``, its middle ``s`` metres
    from the wall's start, showing ``texture`` (tinted by ``color``) into the room."""
    (x0, y0), (x1, y1) = wall.start, wall.end
    ux, uy = (x1 - x0) / wall.length, (y1 - y0) / wall.length
    nx, ny = -uy * side, ux * side
    off = wall.thickness / 2 + 0.011
    return Landmark(position=(x0 + s * ux + off * nx, y0 + s * uy + off * ny), shape="panel",
                    extent=(width, 0.02), height=height, base=base,
                    yaw=math.atan2(ny, nx) - math.pi / 2, color=tuple(color), texture=texture,
                    name=name)


def finish(rng: np.random.Generator, textures: tuple[str, ...], plain: float,
           low: float, high: float, hue: float = 0.06, tint: float = 0.7) -> dict:
    """A wall, floor or furniture finish (``color``, ``texture``): with probability
    ``plain`` no texture and a colour of brightness ``low``-``high`` with a hue of up to
    ``hue`` either way per channel, otherwise one of ``textures`` tinted by a colour of
    channels ``tint``-1."""
    if rng.random() < plain:
        rgb = rng.uniform(low, high) + rng.uniform(-hue, hue, 3)
        return {"color": tuple(float(c) for c in np.clip(rgb, 0, 1)) + (1.0,), "texture": None}
    return {"color": tuple(float(c) for c in rng.uniform(tint, 1.0, 3)) + (1.0,),
            "texture": str(textures[rng.integers(len(textures))])}


def shade(rng: np.random.Generator, rgb, spread: float = 0.1) -> RGB:
    """``rgb`` with each channel moved by up to ``spread`` either way (clipped to [0, 1])."""
    return tuple(float(c) for c in np.clip(np.asarray(rgb) + rng.uniform(-spread, spread, 3),
                                           0, 1))


def windows(rng: np.random.Generator, walls: list[Wall], sides, height: float
             ) -> list[Landmark]:
    """Window bands along the outer walls ``sides``: panes 0.8-2 m wide between thin
    mullions, from 0.8-1.1 m up to 1-1.6 m higher (below the wall top), sky-pale or
    striped blinds, one style per world."""
    base = float(rng.uniform(0.8, 1.1))
    top = min(height - 0.15, base + float(rng.uniform(1.0, 1.6)))
    if rng.random() < 0.35:
        color, texture = tuple(float(c) for c in rng.uniform(0.8, 1.0, 3)) + (1.0,), "stripes_cool"
    else:
        color = (float(rng.uniform(0.7, 0.9)), float(rng.uniform(0.82, 0.95)),
                 float(rng.uniform(0.9, 1.0)), 1.0)
        texture = None
    pane, mullion = float(rng.uniform(0.8, 2.0)), float(rng.uniform(0.08, 0.4))
    panes = []
    for side in sides:
        wall = walls[side]
        inner = wall.length - wall.thickness
        start = float(rng.uniform(0.3, 1.0))
        count = int((inner - 2 * start + mullion) // (pane + mullion))
        first = wall.thickness / 2 + (inner - count * (pane + mullion) + mullion) / 2
        panes += [wall_panel(wall, 1.0, first + i * (pane + mullion) + pane / 2, pane,
                             top - base, base, color, texture, "window") for i in range(count)]
    return panes


def decor(rng: np.random.Generator, wall: Wall, side: float, start: float, end: float,
           count: int) -> list[Landmark]:
    """Up to ``count`` posters, pictures and whiteboards on the ``side`` face of ``wall``
    between ``start`` and ``end`` metres along it, not overlapping."""
    used: list[tuple[float, float]] = []
    panels = []
    for _ in range(count):
        if rng.random() < 0.25:           # a whiteboard
            width, high, base = (float(rng.uniform(1.2, 2.0)), float(rng.uniform(0.9, 1.2)),
                                 float(rng.uniform(0.8, 1.0)))
            color, texture, name = (float(rng.uniform(0.9, 1.0)),) * 3 + (1.0,), None, "whiteboard"
        else:
            width, high, base = (float(rng.uniform(0.4, 1.0)), float(rng.uniform(0.4, 0.9)),
                                 float(rng.uniform(0.9, 1.5)))
            color = tuple(float(c) for c in rng.uniform(0.6, 1.0, 3)) + (1.0,)
            texture, name = str(rng.choice(POSTER_TEXTURES)), "poster"
        if end - start < width + 0.2 or base + high > wall.height - 0.1:
            continue
        s = float(rng.uniform(start + width / 2 + 0.1, end - width / 2 - 0.1))
        if any(abs(s - u) < (width + w) / 2 + 0.1 for u, w in used):
            continue
        used.append((s, width))
        panels.append(wall_panel(wall, side, s, width, high, base, color, texture, name))
    return panels


def wall_decor(rng: np.random.Generator, walls: list[Wall], skip) -> list[Landmark]:
    """Up to 1-3 posters, pictures and whiteboards (:func:`decor`) on the inner face of
    each of the four outer ``walls`` but those of sides ``skip`` (e.g. the windowed ones)."""
    panels = []
    for side in range(4):
        if side not in skip:
            wall = walls[side]
            panels += decor(rng, wall, 1.0, wall.thickness / 2,
                            wall.length - wall.thickness / 2, int(rng.integers(1, 4)))
    return panels
