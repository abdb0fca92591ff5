"""``min-warping``: Möller (2009) and Möller, Krzykawski & Gerstmayr (2010).

Möller 2009, "Local visual homing by warping of two-dimensional images" (Robotics and
Autonomous Systems 57: 87-101), extends the 1-D warping of Franz et al. 1998
(:mod:`homing_baselines.warping`) to two-dimensional panoramas: when the robot moves, a
landmark column keeps its image column *shape* but moves horizontally and is scaled
vertically about the horizon by ``sigma = r_home / r_current`` (the ratio of the
landmark's distances from the two places: nearer looks taller). Möller, Krzykawski &
Gerstmayr 2010, "Three 2D-warping schemes for visual robot navigation" (Autonomous Robots
29: 253-291), give the fast scheme, **min-warping**, that drops Franz's equal-distance
assumption: every column may have its own distance, and the search takes, for each
snapshot column, the best-matching current column among those the movement allows (the
"min" step).

Geometry (home frame, snapshot taken at home ``H``, current place ``P`` at direction
``alpha`` from ``H``, robot rotated by ``psi``): a landmark seen from home at bearing
``x`` and from ``P`` at current-frame bearing ``y`` has home-frame bearing ``y + psi`` from
``P``. With ``u = x - alpha`` and ``v = y + psi - alpha`` the sine rule of the triangle
``H, P, L`` gives the vertical scale ``sigma = r_H / r_P = sin(v) / sin(u)`` and the
relative displacement ``d / r_H = sin(v - u) / sin(v)``; a landmark always moves *away*
from the direction of motion, so ``v`` lies on the same side as ``u`` with ``|v| >= |u|``.

Min-warping (2010, the min-warping section), as implemented here:

1. **Scale-plane stack** (precomputed per image pair, the paper's first phase): for every
   snapshot column ``i``, current column ``j`` and vertical scale ``sigma_k`` from a set
   of ``n_scales`` values geometric in ``[1/scale_max, scale_max]``, the distance
   ``D[k, i, j]`` between the two columns with one of them magnified: the snapshot column
   by ``sigma`` when ``sigma >= 1``, the current column by ``1/sigma`` when ``sigma < 1``
   (the paper's two halves of the stack: magnification only, so no rows are invented
   outside the image).
2. **Search** (the second phase): for every ``alpha`` and ``psi`` on the column grid,
   ``E(alpha, psi) = sum_u min_{v allowed} D[k(u, v), u + alpha, v + alpha - psi]`` with
   ``k(u, v)`` the scale nearest to ``sin(v)/sin(u)`` (clipped to the stack's range) — the
   index table ``k(u, v)`` does not depend on ``alpha`` or ``psi``, so it is precomputed
   once per image width. The minimum of ``E`` gives ``alpha`` and ``psi``; the home
   direction is ``alpha + pi`` in the home frame, ``alpha + pi - psi`` in the robot frame.
   Columns at ``u = 0`` and ``u = pi`` (on the line of motion, where ``sigma`` is not
   determined) match their own ``v`` at any scale.

Our choices (where the papers leave room):

* Image: luminance of the panorama reduced to ``n_columns`` bearing columns (block
  averages, 72 = 5 deg, a resolution of the order the papers use, which keeps the search
  small) and its rows averaged in pairs (48 -> 24 rows, 2.5 deg); each image normalised to
  zero mean and unit standard deviation (robust to a global brightness change; the papers
  compare several column distance measures, we take the plain one).
* Vertical scaling is exact for the cylindrical camera: a row at elevation ``e`` of the
  magnified column samples the original at ``atan(tan(e) / sigma)`` (linear
  interpolation, edge rows repeated). Column distance: sum of squared differences.
* Stop: the matched columns at the best ``(alpha, psi)`` give per-column displacement
  ratios ``d / r_i = |sin(v - u) / sin(v)|``; their median over the informative columns
  (those whose allowed matches do not all cost the same: a uniform wall column ties, and
  a tie would read as "not moved") is a distance estimate in units of landmark distance (as Franz's ``rho``); the robot stops when it is ``<= rho_stop``
  (as :mod:`homing_baselines.warping` stops at ``rho = 0``), or after ``max_steps``.
* Compass-restricted search (the papers' acceleration): with ``psi_window_deg`` < 360
  only the rotations within half the window of a compass estimate are searched, the
  estimate being the rotation that best aligns the two images as if the robot had not
  moved (:func:`compass_shift`, on the stack's unscaled plane, which is computed anyway).
* The search is a numba kernel over ``alpha x psi x (allowed u, v pairs)``: about
  ``n^4 / 4`` table look-ups (4.2 million for 64 columns), ordered so that the innermost
  loop runs over ``psi`` on contiguous memory (vectorised; 2.4 times the speed of the
  loop over ``v`` innermost, the same sums in the same order, so the same result).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

import cv2
import numpy as np
from numba import njit

from homing_baselines.base import Controller
from homing_baselines.motion import Move
from homing_gym.geometry import wrap_angle
from homing_gym.validation import require_number, require_positive
from homing_gym.vision import luminance


#: The controller's number of bearing columns where the panorama is at least as wide.
DEFAULT_COLUMNS = 128


@dataclass(frozen=True)
class MinWarpingConfig:
    """Resolution of min-warping (module doc): ``n_columns`` bearing columns (also the
    ``alpha`` and ``psi`` grid), ``row_pairs`` (average rows in pairs), ``n_scales`` odd
    number of vertical scales geometric in ``[1/scale_max, scale_max]``, the vertical field
    of view ``vfov_deg`` of the panorama, and ``psi_window_deg``: the width of the range of
    rotations ``psi`` searched, centred on the compass estimate (:func:`compass_shift`;
    360: every rotation)."""

    n_columns: int = 64
    row_pairs: bool = True
    n_scales: int = 9
    scale_max: float = 2.0
    vfov_deg: float = 60.0
    psi_window_deg: float = 360.0

    def __post_init__(self) -> None:
        require_number("MinWarpingConfig: n_columns", self.n_columns, 8, 512, "columns",
                       integer=True)
        if self.n_columns % 2:
            raise ValueError(f"MinWarpingConfig: n_columns must be even (u = pi must be a "
                             f"column), got {self.n_columns!r}")
        require_number("MinWarpingConfig: n_scales", self.n_scales, 1, 101, integer=True)
        if self.n_scales % 2 == 0:
            raise ValueError(f"MinWarpingConfig: n_scales must be odd (sigma = 1 is one of "
                             f"them), got {self.n_scales!r}")
        require_number("MinWarpingConfig: scale_max", self.scale_max, 1, 10, low_open=True)
        require_number("MinWarpingConfig: vfov_deg", self.vfov_deg, 1, 179, "degrees")
        require_number("MinWarpingConfig: psi_window_deg", self.psi_window_deg, 0, 360,
                       "degrees", low_open=True)

    def psi_window(self) -> int:
        """How many rotation columns the search covers (odd, at most ``n_columns``)."""
        count = 2 * int(round(self.psi_window_deg / 360 * self.n_columns / 2)) + 1
        return min(count, self.n_columns)

    @property
    def scales(self) -> np.ndarray:
        half = self.n_scales // 2
        if half == 0:
            return np.ones(1)
        return self.scale_max ** (np.arange(-half, half + 1) / half)


@dataclass
class MinWarpResult:
    """Best parameters (radians), home direction in the robot frame, the displacement
    estimate ``rho`` (median ``d / r`` of the matched columns) and the search's cost."""

    alpha: float
    psi: float
    home_direction: float
    rho: float
    cost: float
    costs: np.ndarray = field(repr=False, default=None)


def column_image(panorama: np.ndarray, config: MinWarpingConfig = MinWarpingConfig()
                 ) -> np.ndarray:
    """The min-warping image ``(rows, n_columns)`` float64 of an RGB panorama: luminance,
    columns in bearing order (column ``b`` centred on bearing ``(b + 1/2) 2 pi / n``) as
    block averages, rows averaged in pairs, normalised to zero mean and unit std."""
    image = np.asarray(panorama)
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"panorama must be (H, W, 3), got {image.shape}")
    H, W = image.shape[:2]
    n = config.n_columns
    if W % 2 or n > W:
        raise ValueError(f"the panorama width must be even and >= n_columns={n}, got {W}")
    grey = luminance(image).astype(np.float64)
    # bearing order: bearing (k + 1/2) 2 pi / W sits at column W/2 - 1 - k (mod W); area
    # resampling then centres column b on bearing (b + 1/2) 2 pi / n
    order = (W // 2 - 1 - np.arange(W)) % W
    grey = cv2.resize(grey[:, order], (n, H), interpolation=cv2.INTER_AREA)
    if config.row_pairs and H % 2 == 0:
        grey = grey.reshape(H // 2, 2, n).mean(1)
    std = grey.std()
    return (grey - grey.mean()) / (std if std > 1e-9 else 1.0)


@lru_cache(maxsize=16)
def _scale_matrices(rows: int, scales: tuple[float, ...], vfov_deg: float) -> np.ndarray:
    """(K, rows, rows) linear maps that magnify a column by each scale about the horizon."""
    vfov = math.radians(vfov_deg)
    y = np.arange(rows) + 0.5
    elev = vfov / 2 - vfov * y / rows
    out = np.zeros((len(scales), rows, rows))
    for k, s in enumerate(scales):
        src_elev = np.arctan(np.tan(elev) / s)
        src = (vfov / 2 - src_elev) * rows / vfov - 0.5          # continuous row index
        src = np.clip(src, 0, rows - 1)
        lo = np.floor(src).astype(int)
        hi = np.minimum(lo + 1, rows - 1)
        w = src - lo
        out[k, np.arange(rows), lo] += 1 - w
        out[k, np.arange(rows), hi] += w
    return out


def scale_plane_stack(snapshot: np.ndarray, current: np.ndarray,
                      config: MinWarpingConfig = MinWarpingConfig()) -> np.ndarray:
    """``D[k, i, j]``: squared distance of snapshot column ``i`` and current column ``j``
    at scale ``sigma_k`` (the magnified one of the two, see the module doc)."""
    scales = config.scales
    M = _scale_matrices(snapshot.shape[0], tuple(float(s) for s in scales), config.vfov_deg)
    D = np.empty((len(scales), snapshot.shape[1], current.shape[1]))
    for k, s in enumerate(scales):
        a, b = (M[k] @ snapshot, current) if s >= 1 else (snapshot, M[len(scales) - 1 - k] @ current)
        D[k] = (a ** 2).sum(0)[:, None] + (b ** 2).sum(0)[None, :] - 2 * a.T @ b
    return np.maximum(D, 0.0)


@lru_cache(maxsize=16)
def _pair_table(n: int, scales: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The allowed ``(u, v)`` pairs (column offsets relative to ``alpha``, ``0 .. n-1``)
    grouped by ``u``: ``start[u]:start[u+1]`` index ``v`` and scale index ``k`` (``-1``:
    any scale)."""
    log_s = np.log(np.asarray(scales))
    half = n // 2
    vs, ks, start = [], [], [0]
    for u in range(n):
        us = u if u <= half else u - n                      # signed offset
        if us == 0 or us == half:                           # on the line of motion
            vs.append(u)
            ks.append(-1)
        else:
            sign = 1 if us > 0 else -1
            for vv in range(abs(us), half + 1):
                if vv == half:
                    continue                                 # sin(v) = 0: only for u = pi
                v_signed = sign * vv
                sigma = math.sin(v_signed * 2 * math.pi / n) / math.sin(us * 2 * math.pi / n)
                k = int(np.argmin(np.abs(log_s - math.log(sigma))))
                vs.append(v_signed % n)
                ks.append(k)
        start.append(len(vs))
    return np.array(start), np.array(vs), np.array(ks)


@njit(cache=True)
def _search(Drev: np.ndarray, start: np.ndarray, vs: np.ndarray, ks: np.ndarray,
            n: int, p_lo: int, count: int) -> np.ndarray:
    """E[alpha, psi] = sum_u min_v D[k(u,v), u + alpha, v + alpha - psi] (indices mod n)
    for the ``count`` rotations ``psi = p_lo, p_lo + 1, ...`` (mod n; the others stay
    ``inf``). ``Drev`` is the stack with the any-scale plane appended and its
    current-column axis repeated four times and reversed, so that for one
    ``(alpha, u, v)`` the values of consecutive ``psi`` lie side by side
    (``Drev[k, i, 2n - 1 - v - alpha + psi]``, ``psi < 2n``): the innermost loop runs
    over ``psi`` on a contiguous row, which the compiler vectorises."""
    E = np.full((n, n), np.inf)
    best = np.empty(count)
    for a in range(n):
        total = np.zeros(count)
        for u in range(n):
            i = (u + a) % n
            q0 = start[u]
            row, off = Drev[ks[q0], i], 2 * n - 1 - vs[q0] - a + p_lo
            for p in range(count):
                best[p] = row[off + p]
            for q in range(q0 + 1, start[u + 1]):
                row, off = Drev[ks[q], i], 2 * n - 1 - vs[q] - a + p_lo
                for p in range(count):
                    best[p] = min(best[p], row[off + p])
            for p in range(count):
                total[p] += best[p]
        for p in range(count):
            E[a, (p_lo + p) % n] = total[p]
    return E


def compass_shift(D: np.ndarray, scales: np.ndarray) -> int:
    """The rotation ``psi`` (columns) that best aligns the two images as if the robot had
    not moved: ``argmin_psi sum_i D[sigma = 1, i, i - psi]`` (the unscaled plane of the
    stack), the centre of the rotations searched when ``psi_window_deg`` < 360."""
    n = D.shape[1]
    plane = D[int(np.argmin(np.abs(np.log(scales))))]
    i = np.arange(n)
    return int(np.argmin(plane[i[:, None], (i[:, None] - i[None, :]) % n].sum(0)))


def min_warp(snapshot: np.ndarray, current: np.ndarray,
             config: MinWarpingConfig = MinWarpingConfig()) -> MinWarpResult:
    """Min-warping of two min-warping images (:func:`column_image`): home direction and
    rotation of ``current`` relative to ``snapshot``. Pure function."""
    if snapshot.shape != current.shape:
        raise ValueError(f"snapshot and current must have the same shape, got "
                         f"{snapshot.shape} and {current.shape}")
    n = snapshot.shape[1]
    scales = tuple(float(s) for s in config.scales)
    D = scale_plane_stack(snapshot, current, config)
    start, vs, ks = _pair_table(n, scales)
    Dall = np.concatenate([D, D.min(0)[None]])
    count = config.psi_window()
    p_lo = 0 if count == n else (compass_shift(D, config.scales) - count // 2) % n
    # the reversed stack repeated four times (period n: the same as repeating, then
    # reversing), in one contiguous copy
    E = _search(np.tile(Dall[:, :, ::-1], (1, 1, 4)), start, vs,
                np.where(ks < 0, len(scales), ks), n, p_lo, count)
    a, p = np.unravel_index(int(np.argmin(E)), E.shape)
    step = 2 * np.pi / n
    alpha, psi = (a + 0.5) * step, p * step
    # the matched columns at the optimum: per-column displacement ratios d / r
    u_of = np.repeat(np.arange(n), np.diff(start))
    vals = Dall[np.where(ks < 0, len(scales), ks), (u_of + a) % n, (vs + a - p) % n]
    group_min = np.minimum.reduceat(vals, start[:-1])
    hit = np.flatnonzero(vals <= group_min[u_of])
    _, first = np.unique(u_of[hit], return_index=True)
    v = vs[hit[first]]                                    # the chosen v of every u
    us = (np.arange(n) + n // 2) % n - n // 2
    v_s = (v + n // 2) % n - n // 2
    sv = np.sin(v_s * step)
    safe = np.abs(sv) > 1e-9
    ratios = np.where(safe, np.abs(np.sin((v_s - us) * step)) / np.where(safe, np.abs(sv), 1), 0.0)
    # columns whose allowed matches all cost the same (a uniform wall or sky) say nothing
    # about the displacement: their tie would read as "not moved"
    spread = np.maximum.reduceat(vals, start[:-1]) - group_min
    informative = spread > 1e-6 * max(1.0, float(np.abs(vals).max()))
    rho = float(np.median(ratios[informative])) if informative.any() else 0.0
    return MinWarpResult(alpha=wrap_angle(alpha), psi=wrap_angle(psi),
                         home_direction=wrap_angle(alpha + np.pi - psi),
                         rho=rho, cost=float(E[a, p]), costs=E)


@dataclass
class MinWarpingController(Controller):
    """Min-warping homing (module doc): each decision runs :func:`min_warp` on the current
    panorama and the goal and moves ``step_length`` m in the home direction; it stops
    when the displacement estimate ``rho`` is at most ``rho_stop`` or after ``max_steps``
    moves. The resolution fields are :class:`MinWarpingConfig`'s.

    Defaults chosen on the validation families (``validation-families``: `labs`, `rocky`,
    100 episodes, success under the stop rule): 64 columns 46 % (rocky 6 %: the robot
    stops 0.15-0.3 m short, where distant objects no longer move by a 5.6 degree column),
    96 columns 53 %, 128 columns 65 %, 128 columns with ``psi_window_deg`` = 90 65 % at
    about half the search time; so 128 columns and a 90 degree window. ``n_columns=None``
    (the default) is :data:`DEFAULT_COLUMNS`, or the panorama's width (rounded down to
    even) where it is narrower; a number given is used as it is (a panorama narrower than
    it is a ``ValueError``)."""

    step_length: float = 0.1
    rho_stop: float = 0.0
    max_steps: int = 60
    n_columns: int | None = None
    n_scales: int = MinWarpingConfig.n_scales
    scale_max: float = MinWarpingConfig.scale_max
    psi_window_deg: float = 90.0

    def validate(self) -> None:
        require_positive("min-warping: step_length", self.step_length, "metres")
        require_number("min-warping: rho_stop", self.rho_stop, 0, 1, high_open=True)
        require_number("min-warping: max_steps", self.max_steps, 1, 100_000, integer=True)
        try:
            self.config = MinWarpingConfig(n_columns=(DEFAULT_COLUMNS if self.n_columns is None
                                                      else self.n_columns),
                                           n_scales=self.n_scales, scale_max=self.scale_max,
                                           psi_window_deg=self.psi_window_deg)
        except ValueError as err:
            raise ValueError(f"min-warping: {err}") from None

    def _config_for(self, width: int) -> MinWarpingConfig:
        """The resolution for panoramas ``width`` columns wide (see the class doc)."""
        if self.n_columns is not None:
            return self.config
        return replace(self.config, n_columns=max(8, min(DEFAULT_COLUMNS, width - width % 2)))

    def on_reset(self) -> None:
        self._steps = 0
        self._stopped = False
        self.last_result: MinWarpResult | None = None

    def decide(self, observation) -> Move | None:
        goal = observation["goal"]
        if self.is_new_goal(goal):              # a new target: a new snapshot
            self.config = self._config_for(goal.shape[1])
            self._snapshot = column_image(goal, self.config)
            self._steps, self._stopped = 0, False
        if self._stopped or self._steps >= self.max_steps:
            return None
        current = column_image(observation["panorama"], self.config)
        result = min_warp(self._snapshot, current, self.config)
        self.last_result = result
        if result.rho <= self.rho_stop:
            self._stopped = True
            return None
        self._steps += 1
        return Move(result.home_direction, self.step_length)
