"""Ground-truth shortest paths on the floor of a scene (for the oracle and for SPL).

``shortest_path(scene, start, goal, radius)`` returns the waypoints of a short
collision-free path for a disc of ``radius`` metres: the straight segment when it is free
(exact), otherwise a shortest 8-connected path on an occupancy grid (``resolution``
metres; Dijkstra from ``scipy.sparse.csgraph``) shortened by line-of-sight string pulling
and then tightened like a taut string (any-angle; a few millimetres longer than the true
shortest path). Obstacles are what :func:`homing_gym.scenes.base.clearance` sees:
walls, landmarks and the scene bounds.

``connected(scene, a, b, radius)`` says, without searching, whether ``shortest_path``
finds a path: the free regions of the grid are labelled once per scene
(:func:`regions`, ``scipy.ndimage.label``). Tasks draw every episode's start and goals
joined in this sense at their ``path_radius``, on the grid of :data:`RESOLUTION`, which
is the one the oracle plans on and SPL measures on: a drawn episode always has the path
they use.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

from homing_gym.sim.robot import RobotConfig
from homing_gym.scenes.base import Scene, clearances, per_scene

#: Floor points whose clearances are computed at once (bounds the memory of big worlds).
CHUNK = 1 << 16
#: The robot's body radius (m): the least clearance of any floor point it stands on.
BODY_RADIUS = RobotConfig.body_radius
#: Grid spacing (m) on which episodes are drawn joined, the oracle plans and SPL measures.
RESOLUTION = 0.05
#: A floor point joins the grid through every node within this distance (m) in x and in
#: y, free or not (a robot pushed towards an obstacle may still leave).
ATTACH = 0.06
#: Longest leg (m) of the string pulled taut round obstacles (round a disc of 0.27 m its
#: length comes within 0.3% of the true shortest path's).
TAUT_STEP = 0.08
# the four forward steps (dx >= 0) of the 8-connected grid and their lengths (cells)
_STEPS = ((1, 0, 1.0), (0, 1, 1.0), (1, 1, math.sqrt(2.0)), (1, -1, math.sqrt(2.0)))


class NoPathError(ValueError):
    """Start and goal are not connected for a disc of the given radius."""


@per_scene
def occupancy(scene: Scene, radius: float, resolution: float) -> tuple[np.ndarray, tuple]:
    """Boolean grid, True where a disc of ``radius`` centred on the cell fits; and the
    grid origin ``(xmin, ymin)`` (centre of cell (0, 0)). Cached per scene."""
    (xmin, ymin), (xmax, ymax) = scene.bounds
    nx = int(math.floor((xmax - xmin) / resolution)) + 1
    ny = int(math.floor((ymax - ymin) / resolution)) + 1
    gx, gy = np.meshgrid(xmin + np.arange(nx) * resolution, ymin + np.arange(ny) * resolution,
                         indexing="ij")
    points = np.stack([gx.ravel(), gy.ravel()], axis=1)
    free = np.concatenate([clearances(scene, points[i:i + CHUNK]) >= radius
                           for i in range(0, len(points), CHUNK)])
    return free.reshape(nx, ny), (xmin, ymin)


@per_scene
def regions(scene: Scene, radius: float, resolution: float) -> np.ndarray:
    """The free regions of :func:`occupancy` joined by the grid search's 8-connected moves:
    integer grid of the same shape, 0 where blocked, else the region's label (1, 2, ...).
    Cached per scene."""
    free, _ = occupancy(scene, radius, resolution)
    return ndimage.label(free, structure=np.ones((3, 3), bool))[0]


def connected(scene: Scene, a, b, radius: float = BODY_RADIUS,
              resolution: float = RESOLUTION) -> bool:
    """Whether :func:`shortest_path` with the same arguments finds a path from floor point
    ``a`` to ``b`` (metres), decided without searching it: the straight segment is free,
    or the grid nodes that ``a`` and ``b`` join (:data:`ATTACH`) touch one free region
    (:func:`regions`), or touch each other."""
    return segment_free(scene, a, b, radius) or bool(
        _grid_joined(scene, np.array([a[:2]]), np.array([b[:2]]), radius, resolution)[0])


def joined_in_order(scene: Scene, points, radius: float = BODY_RADIUS,
                    resolution: float = RESOLUTION) -> np.ndarray:
    """Whether each of ``points`` ``(N, 2+)`` (metres; extra columns such as a yaw are
    ignored) is joined to the next as :func:`connected` says: ``(N - 1,)`` bools, from one
    labelling of the grid for all pairs, with segment checks only for the pairs the grid
    does not join (a route of thousands of points is checked in milliseconds)."""
    pts = np.asarray(points, dtype=np.float64)[:, :2]
    joined = _grid_joined(scene, pts[:-1], pts[1:], radius, resolution)
    for i in np.flatnonzero(~joined):
        joined[i] = segment_free(scene, pts[i], pts[i + 1], radius)
    return joined


def _grid_joined(scene: Scene, a: np.ndarray, b: np.ndarray, radius: float,
                 resolution: float) -> np.ndarray:
    """For floor points ``a[i]`` and ``b[i]`` (``(M, 2)`` metres): whether the grid nodes
    they join (:data:`ATTACH`) touch each other or one free region (:func:`regions`)."""
    labels, k = regions(scene, radius, resolution), _attach_cells(resolution)
    ends_a, ends_b = _nodes(scene, a, radius, resolution), _nodes(scene, b, radius, resolution)
    near = np.max(np.abs(ends_a - ends_b), axis=1) <= 2 * k + 1
    reach = np.arange(-(k + 1), k + 2)              # the attached nodes and their neighbours
    padded = np.pad(labels, k + 1)                  # 0 (blocked) beyond the grid

    def around(ends: np.ndarray) -> np.ndarray:
        ix = ends[:, 0, None, None] + k + 1 + reach[None, :, None]
        iy = ends[:, 1, None, None] + k + 1 + reach[None, None, :]
        return padded[ix, iy].reshape(len(ends), -1)

    la, lb = around(ends_a), around(ends_b)
    shared = ((la[:, :, None] == lb[:, None, :]) & (la[:, :, None] > 0)).any(axis=(1, 2))
    return near | shared


def segment_free(scene: Scene, a, b, radius: float, step: float = 0.01) -> bool:
    """Whether a disc of ``radius`` can slide from ``a`` to ``b`` (checked every ``step`` m;
    extra coordinates such as a yaw are ignored)."""
    a, b = (float(a[0]), float(a[1])), (float(b[0]), float(b[1]))
    n = max(1, int(math.ceil(math.dist(a, b) / step)))
    t = np.arange(n + 1)[:, None] / n
    points = np.asarray(a) + t * (np.asarray(b) - np.asarray(a))
    return bool(np.all(clearances(scene, points) >= radius))


def path_length(points) -> float:
    """Length (metres) of a polyline given as a sequence of (x, y, ...) points."""
    pts = np.asarray(points, dtype=np.float64)
    if len(pts) < 2:
        return 0.0
    return float(np.sum(np.hypot(*np.diff(pts[:, :2], axis=0).T)))


def shortest_path(scene: Scene, start, goal, radius: float = BODY_RADIUS,
                  resolution: float = RESOLUTION) -> list[tuple[float, float]]:
    """Waypoints ``[start, ..., goal]`` (metres) of a short free path; see the module doc.

    Raises :class:`NoPathError` when the grid search finds no connection (exactly when
    :func:`connected` is false).
    """
    a, b = (float(start[0]), float(start[1])), (float(goal[0]), float(goal[1]))
    if segment_free(scene, a, b, radius):
        return [a, b]
    free, (x0, y0) = occupancy(scene, radius, resolution)

    def centre(c) -> tuple[float, float]:
        return x0 + c[0] * resolution, y0 + c[1] * resolution

    src, dst = _ends(scene, a, b, radius, resolution)
    free = free.copy()
    for c in (src, dst):
        free[_block(c, _attach_cells(resolution))] = True
    cells = _grid_path(free, src, dst)
    if cells is None:
        raise NoPathError(f"no free path for radius {radius} m from {a} to {b} "
                          f"in scene {scene.name!r}")
    points = [a] + [centre(c) for c in cells[1:-1]] + [b]
    visible = lambda p, q: segment_free(scene, p, q, radius)  # noqa: E731
    return _tighten(_subdivide(_string_pull(points, visible), TAUT_STEP), visible)


def _ends(scene: Scene, a, b, radius: float, resolution: float) -> list[tuple[int, int]]:
    """The grid nodes nearest to floor points ``a`` and ``b``."""
    nodes = _nodes(scene, np.array([a[:2], b[:2]], dtype=np.float64), radius, resolution)
    return [(int(i), int(j)) for i, j in nodes]


def _nodes(scene: Scene, points: np.ndarray, radius: float, resolution: float) -> np.ndarray:
    """The grid nodes ``(M, 2)`` (indices) nearest to floor points ``(M, 2)`` (metres)."""
    free, origin = occupancy(scene, radius, resolution)
    nodes = np.rint((points - np.asarray(origin)) / resolution).astype(np.int64)
    return np.clip(nodes, 0, np.array(free.shape) - 1)


def _attach_cells(resolution: float) -> int:
    """:data:`ATTACH` in grid steps (at least one)."""
    return max(1, int(round(ATTACH / resolution)))


def _block(cell: tuple[int, int], k: int) -> tuple[slice, slice]:
    """The nodes within ``k`` steps of ``cell`` in x and in y."""
    return slice(max(0, cell[0] - k), cell[0] + k + 1), slice(max(0, cell[1] - k), cell[1] + k + 1)


def _grid_path(free: np.ndarray, src, dst) -> list | None:
    """Cells of a shortest 8-connected path from ``src`` to ``dst`` over ``free`` cells
    (steps of 1 and sqrt(2) cells; ``dst`` counts as free): Dijkstra from
    ``scipy.sparse.csgraph`` on the grid graph. ``None`` when they are not connected."""
    nx, ny = free.shape
    free = free.copy()
    free[dst] = True
    index = np.arange(nx * ny).reshape(nx, ny)
    rows, cols, costs = [], [], []
    for dx, dy, cost in _STEPS:
        a = (slice(0, nx - dx), slice(max(0, -dy), ny - max(0, dy)))
        b = (slice(dx, nx), slice(max(0, dy), ny - max(0, -dy)))
        both = free[a] & free[b]
        rows.append(index[a][both])
        cols.append(index[b][both])
        costs.append(np.full(int(both.sum()), cost))
    graph = coo_matrix((np.concatenate(costs), (np.concatenate(rows), np.concatenate(cols))),
                       shape=(nx * ny, nx * ny)).tocsr()
    source, target = int(index[src]), int(index[dst])
    dist, parent = dijkstra(graph, directed=False, indices=source, return_predecessors=True)
    if not np.isfinite(dist[target]):
        return None
    path = [target]
    while path[-1] != source:
        path.append(int(parent[path[-1]]))
    return [divmod(i, ny) for i in reversed(path)]


def _string_pull(points: list, visible) -> list:
    """Keep from each kept waypoint only the farthest later one it can see
    (``visible(p, q)``: the straight move p -> q is free)."""
    kept = [points[0]]
    i = 0
    while i < len(points) - 1:
        j = len(points) - 1
        while j > i + 1 and not visible(points[i], points[j]):
            j -= 1
        kept.append(points[j])
        i = j
    return kept


def _tighten(points: list, visible, rounds: int = 100, tol: float = 1e-4) -> list:
    """Pull each inner waypoint towards the chord of its neighbours while both legs stay
    free, until the length stops shrinking; then drop the waypoints that can be skipped."""
    pts = [tuple(p) for p in points]
    length = path_length(pts)
    for _ in range(rounds):
        i = 1
        while i < len(pts) - 1:
            a, p, b = pts[i - 1], pts[i], pts[i + 1]
            ab = (b[0] - a[0], b[1] - a[1])
            t = max(0.0, min(1.0, ((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1])
                             / (ab[0] ** 2 + ab[1] ** 2)))
            m = (a[0] + t * ab[0], a[1] + t * ab[1])
            for f in (0.5, 0.25, 0.125, 0.0625):
                q = (p[0] + f * (m[0] - p[0]), p[1] + f * (m[1] - p[1]))
                if visible(a, q) and visible(q, b):
                    pts[i] = q
                    break
            i += 1
        new = path_length(pts)
        if length - new < tol:
            break
        length = new
    return _string_pull(pts, visible)


def _subdivide(points: list, max_step: float) -> list:
    """Insert evenly spaced points so that no leg is longer than ``max_step`` metres."""
    out = [points[0]]
    for p, q in zip(points[:-1], points[1:]):
        n = max(1, int(math.ceil(math.dist(p, q) / max_step)))
        out += [(p[0] + (q[0] - p[0]) * k / n, p[1] + (q[1] - p[1]) * k / n)
                for k in range(1, n + 1)]
    return out
