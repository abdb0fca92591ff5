"""``distance``: landmark navigation with distance estimation (Yu & Kim 2011).

The method (Yu & Kim, "Distance Estimation Method with Snapshot Landmark Images in the
Robotic Homing Navigation", §II):

1. Two snapshots one step apart (§II-A, Fig. 1): a landmark at bearing θ before the step
   appears at θ + δ after it. With step length ``d`` and ψ the rotation before the step
   (the angle between the initial heading and the motion direction), its distance from
   the second position T is Eq. 1, ``R = d sin(θ - ψ) / sin(δ + ψ)``. The heading is held
   fixed across the step (ψ = 0) in the controller; the functions take any ψ.
2. With R and the bearing θ + δ of every landmark, the robot draws its *egocentric map*
   (§II-B, Fig. 3). At the nest the same procedure gives the *environmental map*
   (:class:`NestMap`, landmark positions in the nest frame).
3. Correspondence by arrangement order (§II-B): every assignment of the current
   landmarks to the map's that keeps their counter-clockwise order (the cyclic shifts,
   ``assignments="cyclic"``; ``"all"`` tries every injective assignment) gives a rigid
   fit of the egocentric map onto the nest map; each landmark then yields one estimate of
   the robot position. The right arrangement is the one whose estimates *converge*: the
   smallest RMS spread of the per-landmark position estimates (:func:`localize`); a
   landmark with a distance in only one of the two maps adds its lateral offset from the
   bearing seen in the other (:func:`_bearing_terms`).
4. The pose in the nest frame gives the home direction and distance; step home, repeat.

Degenerate cases of Eq. 1 (:func:`landmark_distances`): a landmark within
``min_axis_deg`` of the line of motion (``sin(θ - ψ) -> 0``) barely shifts, so δ is
dominated by pixel noise and R is 0/0; a shift δ + ψ below ``min_parallax_deg`` gives an
unbounded R; a negative R (δ of the wrong sign, noise) or one beyond ``max_range`` is
impossible. Such landmarks get no distance (NaN, with the reason in the diagnostics);
they still count for the arrangement order but not for the position fit. With fewer
than two measured landmarks the pose is unknown and the controller walks towards the landmark
group, keeping it 45° off its heading, and measures again
(:meth:`DistanceController._fallback`).

Arrival (our choice: the paper states none). §II-B ends the loop with "After determining
the homing direction, the agent can move one step forward and obtain the next snapshot
image in order to compute the appropriate next moving direction. This procedure is
repeated."; §III scores "the number of successes out of 100 trials" without saying what
a success or an arrival is. A threshold on the estimated distance at the measuring place
cannot serve: every measurement is taken one probing step (``step_length``) after the
place the robot stood at, so near the nest the robot measures about a step away from it
and an estimate below a few centimetres almost never comes (the former rule, estimate <
``arrive_tolerance``, stopped in 12 of 100 ``yukim`` episodes that came within 0.15 m in
94). The controller therefore decides arrival from two of the method's own estimates
(:func:`arrival_confirmed`): when the current estimate puts the nest within one move
(``move_length``: the move then ends at the estimated nest) *and* it agrees, within
``confirm_tolerance`` (default one step length, 0.15 m), with the previous estimate carried
forward by the moves commanded since (the planned actions, never odometry), the robot
drives the whole estimated distance home and stops there. The agreement test rejects the
single wrong localisations (a wrong cyclic shift, two landmarks only) that otherwise
stop the robot far from the nest; its tolerance is the step length because Eq. 1's
errors near the nest are a few centimetres (docs/yu_kim.md) and a disagreement of a whole
step means one of the two estimates is wrong. Chosen from the method and checked on
reseeded ``yukim`` draws (seeds 500 and 700), never on the protocol's own episodes.

The nest map. The paper's robot measured the nest map with two snapshots at the nest.
The env's observation holds one nest snapshot (``goal``). :class:`DistanceController`
therefore uses, in order of preference:

* ``nest="goal_step"``: an observation key ``goal_step`` holding the panorama the robot
  would see at the nest after one step of ``nest_step`` metres straight ahead (heading
  unchanged): the paper's procedure exactly (env option requested, see ``docs/yu_kim.md``);
* ``nest="resection"`` (interim, default when ``goal_step`` is absent): at each
  measurement the egocentric map (metric, from Eq. 1) and the nest snapshot's bearings
  locate the nest in the egocentric frame by resection (bearing-only localisation of
  the nest against at least three measured landmarks, every assignment tried,
  accepted below 5° RMS bearing residual, :func:`resect_nest_map`), which gives the
  landmark positions in the nest frame; the nest map is the running mean of these
  estimates over the episode. The paper's localisation (step 3) then runs on it.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import ClassVar, Sequence

import numpy as np

from homing_baselines.base import Controller
from homing_baselines.landmarks_red import Arc, RedSegmentation, detect_landmarks
from homing_baselines.motion import Move, integrate
from homing_gym.geometry import wrap_angle
from homing_gym.validation import require_positive

ASSIGNMENT_MODES = ("cyclic", "all")


# -- Eq. 1 ---------------------------------------------------------------------------------
def eq1_distance(theta, delta, step: float, psi: float = 0.0):
    """Eq. 1: distance R (metres) of a landmark from the second snapshot position,
    ``R = d sin(θ - ψ) / sin(δ + ψ)``; θ the bearing before the step, δ its shift, ψ the
    rotation before stepping (radians). No degenerate-case handling: see
    :func:`landmark_distances`."""
    theta, delta = np.asarray(theta, np.float64), np.asarray(delta, np.float64)
    return step * np.sin(theta - psi) / np.sin(delta + psi)


@dataclass(frozen=True)
class DistanceConfig:
    """Parameters of distance estimation and localisation (degrees, metres).

    ``max_match_deg``: largest bearing change of one landmark across a step (after
    removing ψ) for the two views' arcs to be paired.
    """

    min_axis_deg: float = 10.0
    min_parallax_deg: float = 0.3
    max_range: float = 6.0
    max_match_deg: float = 30.0
    assignments: str = "cyclic"
    segmentation: RedSegmentation = RedSegmentation()

    def __post_init__(self) -> None:
        if not 0 <= self.min_axis_deg < 90:
            raise ValueError(f"min_axis_deg must be in [0, 90), got {self.min_axis_deg!r}")
        if not self.min_parallax_deg >= 0:
            raise ValueError(f"min_parallax_deg must be >= 0, got {self.min_parallax_deg!r}")
        if not self.max_range > 0:
            raise ValueError(f"max_range must be positive metres, got {self.max_range!r}")
        if not 0 < self.max_match_deg <= 180:
            raise ValueError(f"max_match_deg must be in (0, 180], got {self.max_match_deg!r}")
        if self.assignments not in ASSIGNMENT_MODES:
            raise ValueError(f"assignments must be one of {ASSIGNMENT_MODES}, "
                             f"got {self.assignments!r}")


@dataclass(frozen=True)
class LandmarkMap:
    """Landmarks seen from one place, counter-clockwise by ``bearings`` (radians, in the
    frame of that place's heading); ``distances`` (m, NaN where Eq. 1 gave none) and
    ``status`` ("ok" or why not). ``positions``: (n, 2), NaN rows where unknown.

    As an egocentric map (§II-B) the frame is the robot at the second snapshot; as the
    environmental (nest) map it is the nest pose.
    """

    bearings: np.ndarray
    distances: np.ndarray
    widths: np.ndarray
    status: tuple[str, ...]

    @property
    def positions(self) -> np.ndarray:
        return self.distances[:, None] * np.column_stack([np.cos(self.bearings),
                                                          np.sin(self.bearings)])

    @property
    def valid(self) -> np.ndarray:
        return np.isfinite(self.distances)

    def __len__(self) -> int:
        return int(self.bearings.size)


NestMap = LandmarkMap


def map_from_positions(positions: np.ndarray, widths: np.ndarray | None = None) -> LandmarkMap:
    """A map from landmark positions (n, 2) in its own frame (NaN rows: bearing unknown
    is not allowed, give finite rows), sorted counter-clockwise."""
    positions = np.asarray(positions, np.float64).reshape(-1, 2)
    bearings = np.arctan2(positions[:, 1], positions[:, 0])
    order = np.argsort(bearings)
    w = np.zeros(len(positions)) if widths is None else np.asarray(widths, np.float64)
    return LandmarkMap(bearings[order], np.hypot(*positions.T)[order], w[order],
                       ("ok",) * len(positions))


def match_step(arcs0: Sequence[Arc], arcs1: Sequence[Arc], psi: float = 0.0,
               max_shift: float = math.radians(30)) -> list[tuple[int, int]]:
    """Pairs (i0, i1) of the same landmark in the views before and after a step: mutual
    nearest bearings, ``θ1 ≈ θ0 - ψ``, within ``max_shift`` radians."""
    if not arcs0 or not arcs1:
        return []
    b0 = np.array([a.bearing for a in arcs0]) - psi
    b1 = np.array([a.bearing for a in arcs1])
    diff = np.abs(wrap_angle(b1[None, :] - b0[:, None]))  # (n0, n1)
    pairs = []
    for i0 in range(len(arcs0)):
        i1 = int(np.argmin(diff[i0]))
        if int(np.argmin(diff[:, i1])) == i0 and diff[i0, i1] <= max_shift:
            pairs.append((i0, i1))
    return pairs


def landmark_distances(arcs0: Sequence[Arc], arcs1: Sequence[Arc], step: float,
                       psi: float = 0.0, config: DistanceConfig = DistanceConfig()
                       ) -> LandmarkMap:
    """The egocentric map at the second snapshot (§II-B): every landmark of view 1 with
    its Eq. 1 distance, or NaN and the reason (see the module doc for the cases)."""
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step must be a positive length in metres, got {step!r}")
    pairs = dict((i1, i0) for i0, i1 in match_step(arcs0, arcs1, psi,
                                                   math.radians(config.max_match_deg)))
    n = len(arcs1)
    distances = np.full(n, np.nan)
    status = []
    for i1 in range(n):
        if i1 not in pairs:
            status.append("unmatched")
            continue
        theta = arcs0[pairs[i1]].bearing
        delta = wrap_angle(arcs1[i1].bearing - theta)
        if abs(math.sin(theta - psi)) < math.sin(math.radians(config.min_axis_deg)):
            status.append("on motion axis")
            continue
        if abs(wrap_angle(delta + psi)) < math.radians(config.min_parallax_deg):
            status.append("no parallax")
            continue
        r = float(eq1_distance(theta, delta, step, psi))
        if not 0 < r <= config.max_range:
            status.append("out of range")
            continue
        distances[i1] = r
        status.append("ok")
    return LandmarkMap(np.array([a.bearing for a in arcs1]), distances,
                       np.array([a.width for a in arcs1]), tuple(status))


def build_nest_map(view0: np.ndarray, view1: np.ndarray, step: float, psi: float = 0.0,
                   config: DistanceConfig = DistanceConfig()) -> LandmarkMap:
    """The environmental map (§II, §III: "the robot draws an environmental map by
    estimating the distance of each landmark") from two panoramas at the nest: ``view0``
    at the nest, ``view1`` after turning ψ and stepping ``step`` metres. Positions are
    re-expressed in the frame of the nest pose (``view0``)."""
    seg = config.segmentation
    arcs0, arcs1 = detect_landmarks(view0, seg), detect_landmarks(view1, seg)
    ego = landmark_distances(arcs0, arcs1, step, psi, config)
    c, s = math.cos(psi), math.sin(psi)
    p = ego.positions
    q = np.column_stack([step * c + c * p[:, 0] - s * p[:, 1],
                         step * s + s * p[:, 0] + c * p[:, 1]])
    # keep the nest view's own bearings for landmarks without a distance
    bearings = np.where(ego.valid, np.arctan2(q[:, 1], q[:, 0]), np.nan)
    pairs = dict((i1, i0) for i0, i1 in match_step(arcs0, arcs1, psi,
                                                   math.radians(config.max_match_deg)))
    for i in np.flatnonzero(~ego.valid):
        bearings[i] = arcs0[pairs[i]].bearing if i in pairs else ego.bearings[i] + psi
    order = np.argsort(bearings)
    return LandmarkMap(bearings[order], np.hypot(q[:, 0], q[:, 1])[order],
                       ego.widths[order], tuple(ego.status[i] for i in order))


# -- correspondence and localisation (§II-B) -------------------------------------------------
def _order_preserving(js: Sequence[int], n: int) -> bool:
    """True if ``js`` visits its indices counter-clockwise (a cyclic shift of increasing)."""
    steps = [(js[(k + 1) % len(js)] - js[k]) % n for k in range(len(js))]
    return sum(steps) == n or len(js) <= 1


def assignments(n_current: int, n_map: int, mode: str = "cyclic") -> list[list[tuple[int, int]]]:
    """Candidate correspondences as lists of (current index, map index) pairs: every
    injective assignment of the smaller set into the larger; ``"cyclic"`` keeps only those
    that preserve the counter-clockwise arrangement order (§II-B)."""
    if mode not in ASSIGNMENT_MODES:
        raise ValueError(f"mode must be one of {ASSIGNMENT_MODES}, got {mode!r}")
    m = min(n_current, n_map)
    out = []
    if m == 0:
        return out
    if n_current <= n_map:
        for js in itertools.permutations(range(n_map), n_current):
            if mode == "all" or _order_preserving(js, n_map):
                out.append(list(zip(range(n_current), js)))
    else:
        for is_ in itertools.permutations(range(n_current), n_map):
            if mode == "all" or _order_preserving(is_, n_current):
                out.append(list(zip(is_, range(n_map))))
    return out


@dataclass(frozen=True)
class PoseEstimate:
    """Robot pose in the nest frame (x, y metres; ``heading`` radians), the RMS
    ``spread`` (m) of the per-landmark position estimates, the assignment used
    (current index, map index) and how many landmarks entered the fit."""

    x: float
    y: float
    heading: float
    spread: float
    assignment: tuple[tuple[int, int], ...]
    n_used: int

    @property
    def home_distance(self) -> float:
        return math.hypot(self.x, self.y)

    @property
    def home_direction(self) -> float:
        """Direction of the nest in the robot frame (radians, CCW from heading)."""
        return wrap_angle(math.atan2(-self.y, -self.x) - self.heading)


def rigid_fit(p: np.ndarray, q: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """Rotation φ and per-landmark translations with ``q_i ≈ R(φ) p_i + t_i``: φ is the
    least-squares rotation (2-D Kabsch); ``t_i = q_i - R(φ) p_i`` are the position
    estimates of the robot, one per landmark. Returns (φ, t_i (n, 2), their mean)."""
    pc, qc = p - p.mean(0), q - q.mean(0)
    phi = math.atan2(float(np.sum(pc[:, 0] * qc[:, 1] - pc[:, 1] * qc[:, 0])),
                     float(np.sum(pc * qc)))
    c, s = math.cos(phi), math.sin(phi)
    t = q - p @ np.array([[c, s], [-s, c]])
    return phi, t, t.mean(0)


def localize(ego: LandmarkMap, nest: LandmarkMap, mode: str = "cyclic"
             ) -> tuple[PoseEstimate | None, list[PoseEstimate]]:
    """§II-B: the pose for every candidate arrangement, and the one whose per-landmark
    position estimates converge best (smallest RMS spread) among the candidates with
    the most landmarks measured in both maps (at least two). ``(None, [])`` if none."""
    p_all, q_all = ego.positions, nest.positions
    candidates = []
    for pairs in assignments(len(ego), len(nest), mode):
        used = [(i, j) for i, j in pairs if ego.valid[i] and nest.valid[j]]
        if len(used) < 2:
            continue
        p = p_all[[i for i, _ in used]]
        q = q_all[[j for _, j in used]]
        phi, t, mean = rigid_fit(p, q)
        terms = list(np.sum((t - mean) ** 2, axis=1))
        terms += _bearing_terms(ego, nest, pairs, phi, mean)
        spread = float(np.sqrt(np.mean(terms)))
        candidates.append(PoseEstimate(float(mean[0]), float(mean[1]), wrap_angle(phi),
                                       spread, tuple(pairs), len(used)))
    if not candidates:
        return None, []
    most = max(c.n_used for c in candidates)
    best = min((c for c in candidates if c.n_used == most), key=lambda c: c.spread)
    return best, candidates


def _bearing_terms(ego: LandmarkMap, nest: LandmarkMap, pairs, phi: float,
                   t: np.ndarray) -> list[float]:
    """Squared lateral offsets (m²) of the landmarks of an arrangement that have a distance
    in one map only: their position from that map, carried over by the candidate pose,
    must lie on the bearing seen in the other. With two landmarks measured in both maps
    every arrangement whose two inter-landmark distances agree fits exactly; these
    bearings are what lets the right one still converge best (§II-B's criterion applied
    to every landmark of the arrangement)."""
    c, s = math.cos(phi), math.sin(phi)
    out = []
    for i, j in pairs:
        if nest.valid[j] and not ego.valid[i]:
            v = nest.positions[j] - t  # nest landmark relative to the robot, nest frame
            rel = np.array([c * v[0] + s * v[1], -s * v[0] + c * v[1]])  # robot frame
            err = wrap_angle(math.atan2(rel[1], rel[0]) - ego.bearings[i])
        elif ego.valid[i] and not nest.valid[j]:
            p = ego.positions[i]
            rel = np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]]) + t  # nest frame
            err = wrap_angle(math.atan2(rel[1], rel[0]) - nest.bearings[j])
        else:
            continue
        out.append(float(np.hypot(*rel) * math.sin(min(abs(err), math.pi / 2))) ** 2)
    return out


def resect_nest_map(ego: LandmarkMap, nest_bearings: np.ndarray, mode: str = "cyclic",
                    phi_step_deg: float = 1.0) -> tuple[LandmarkMap | None, float]:
    """Interim nest map from one nest snapshot: locate the nest pose in the egocentric
    frame from the nest view's landmark bearings (resection, at least 3 measured
    landmarks) and express the measured landmarks in the nest frame.

    For each arrangement (as in §II-B) and each nest heading φ on a ``phi_step_deg`` grid
    (refined to 0.01°), the nest position h is the least-squares point on the bearing
    lines ``p_i - h ∥ (cos(β_j + φ), sin(β_j + φ))``; the arrangement and φ with the
    smallest RMS angular residual win. Returns (map, RMS residual in radians) or
    (None, inf)."""
    nest_bearings = np.sort(np.asarray(nest_bearings, np.float64))
    pos = ego.positions
    best = (math.inf, None, None, None)
    for pairs in assignments(len(ego), len(nest_bearings), mode):
        used = [(i, j) for i, j in pairs if ego.valid[i]]
        if len(used) < 3:
            continue
        p = pos[[i for i, _ in used]]
        beta = nest_bearings[[j for _, j in used]]
        grid = np.radians(np.arange(-180, 180, phi_step_deg))
        for fine in (False, True):
            res, hs = _resection_residuals(p, beta, grid)
            k = int(np.argmin(res))
            if not fine:
                grid = grid[k] + np.radians(np.arange(-phi_step_deg, phi_step_deg, 0.01))
        if res[k] < best[0]:
            best = (float(res[k]), float(grid[k]), hs[k], pairs)
    rms, phi, h, pairs = best
    if pairs is None:
        return None, math.inf
    c, s = math.cos(phi), math.sin(phi)
    q = (pos - h) @ np.array([[c, -s], [s, c]])  # rows: R(-φ) (p - h)
    n = len(nest_bearings)
    positions = np.full((n, 2), np.nan)
    for i, j in pairs:
        if ego.valid[i]:
            positions[j] = q[i]
    dist = np.hypot(positions[:, 0], positions[:, 1])
    status = tuple("ok" if np.isfinite(d) else "unmeasured" for d in dist)
    return LandmarkMap(nest_bearings, dist, np.zeros(n), status), rms


def _resection_residuals(p: np.ndarray, beta: np.ndarray, phis: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray]:
    """RMS angular residual and least-squares nest position for each heading in ``phis``."""
    ang = beta[None, :] + phis[:, None]  # (k, n)
    nx, ny = -np.sin(ang), np.cos(ang)  # normals of the bearing lines
    # normal equations of sum_i (n_i . (p_i - h))^2 over h
    a11, a12, a22 = (nx * nx).sum(1), (nx * ny).sum(1), (ny * ny).sum(1)
    rhs = nx * p[None, :, 0] + ny * p[None, :, 1]
    b1, b2 = (nx * rhs).sum(1), (ny * rhs).sum(1)
    det = a11 * a22 - a12 ** 2
    det = np.where(np.abs(det) < 1e-12, np.nan, det)
    h = np.column_stack([(a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det])
    v = p[None, :, :] - h[:, None, :]  # (k, n, 2)
    err = wrap_angle(np.arctan2(v[..., 1], v[..., 0]) - ang)
    res = np.sqrt(np.mean(err ** 2, axis=1))
    return np.where(np.isfinite(res), res, np.inf), h


# -- the pure homing function --------------------------------------------------------------
@dataclass
class Diagnostics:
    """What one distance-homing decision saw: the arcs of both views, the egocentric map,
    every candidate arrangement's pose, and why it failed (empty if it did not)."""

    arcs0: list[Arc]
    arcs1: list[Arc]
    ego: LandmarkMap
    candidates: list[PoseEstimate] = field(default_factory=list)
    failure: str = ""


def distance_homing(view0: np.ndarray, view1: np.ndarray, step: float, nest_map: LandmarkMap,
                    psi: float = 0.0, config: DistanceConfig = DistanceConfig()
                    ) -> tuple[PoseEstimate | None, float | None, Diagnostics]:
    """One decision of Yu & Kim's method from two panoramas one step apart.

    ``view0`` before the step, ``view1`` after turning ψ and moving ``step`` metres;
    ``nest_map`` the environmental map. Returns (pose of the robot at ``view1`` in the
    nest frame, home direction in its robot frame (radians), diagnostics); pose and
    direction are None when fewer than two landmarks could be localised.
    """
    seg = config.segmentation
    arcs0, arcs1 = detect_landmarks(view0, seg), detect_landmarks(view1, seg)
    ego = landmark_distances(arcs0, arcs1, step, psi, config)
    diag = Diagnostics(arcs0, arcs1, ego)
    pose, diag.candidates = localize(ego, nest_map, config.assignments)
    if pose is None:
        diag.failure = (f"fewer than 2 landmarks with distances in both maps "
                        f"(ego status {ego.status}, map status {nest_map.status})")
        return None, None, diag
    return pose, pose.home_direction, diag


# -- obstacles (our addition) ---------------------------------------------------------------
def view_obstacles(arcs: Sequence[Arc], ego: LandmarkMap | None, radius: float
                   ) -> list[tuple[float, float, float]]:
    """Landmarks of the current view as discs (x, y, r) in the robot frame (metres).
    Where Eq. 1 measured the distance R (``ego``), the disc is at R with r = R sin(w/2)
    from the angular width w; elsewhere the distance follows from the width and
    ``radius``: R = radius / sin(w/2) (merged arcs look wider, hence nearer: cautious)."""
    out = []
    measured = {}
    if ego is not None:
        measured = {round(float(b), 9): float(r) for b, r in zip(ego.bearings, ego.distances)
                    if np.isfinite(r)}
    for a in arcs:
        half = min(max(a.width / 2, 1e-3), math.pi / 2)
        r = measured.get(round(float(a.bearing), 9))
        if r is not None:
            rad = r * math.sin(half)
        else:
            rad = radius
            r = radius / math.sin(half)
        out.append((r * math.cos(a.bearing), r * math.sin(a.bearing), rad))
    return out


def free_direction(direction: float, length: float, obstacles, clearance: float,
                   resolution: float = math.radians(5)) -> float | None:
    """The direction nearest ``direction`` (robot frame, radians) along which a straight
    path of ``length`` m keeps ``clearance`` m between the robot centre and every disc of
    ``obstacles``; from inside that margin, only directions leading away are free.
    None if no direction is free."""
    for k in range(int(math.pi / resolution) + 1):
        for sign in ((1,) if k == 0 else (1, -1)):
            d = wrap_angle(direction + sign * k * resolution)
            u = np.array([math.cos(d), math.sin(d)])
            if all(_clear(u, length, ob, clearance) for ob in obstacles):
                return float(d)
    return None


def _clear(u: np.ndarray, length: float, ob, clearance: float) -> bool:
    c = np.array(ob[:2])
    need = clearance + ob[2]
    d0 = float(np.hypot(*c))
    if d0 < need:
        return float(u @ c) <= 0.0
    t = min(max(float(u @ c), 0.0), length)
    return float(np.hypot(*(c - t * u))) >= need


def _blocked(ego: LandmarkMap) -> bool:
    """True when a measuring step moved no landmark: none measured or out of range, at
    least one without parallax (the robot pushed against an obstacle)."""
    return "no parallax" in ego.status and not any(s in ("ok", "out of range")
                                                     for s in ego.status)


# -- arrival (our choice, see the module doc) ----------------------------------------------
def carry_forward(estimate: PoseEstimate, motion: Sequence[float]) -> np.ndarray:
    """The pose (x, y, heading) in the nest frame that ``estimate`` predicts after the
    robot moved by ``motion`` = (dx, dy, dyaw) in its own frame at the estimate."""
    c, s = math.cos(estimate.heading), math.sin(estimate.heading)
    dx, dy, dyaw = (float(v) for v in motion)
    return np.array([estimate.x + c * dx - s * dy, estimate.y + s * dx + c * dy,
                     wrap_angle(estimate.heading + dyaw)])


def arrival_confirmed(previous: PoseEstimate | None, motion: Sequence[float] | None,
                      current: PoseEstimate, reach: float, tolerance: float) -> bool:
    """The arrival rule: the nest lies within ``reach`` metres of the ``current``
    estimate (one move gets there) and the ``previous`` estimate, carried forward by the
    robot's commanded ``motion`` since (dx, dy, dyaw in the frame of the previous
    estimate), puts the robot within ``tolerance`` metres of where ``current`` does.
    False without a previous estimate."""
    if previous is None or motion is None or current.home_distance > reach:
        return False
    predicted = carry_forward(previous, motion)
    return math.hypot(predicted[0] - current.x, predicted[1] - current.y) <= tolerance


# -- the controller --------------------------------------------------------------------------
NEST_SOURCES = ("auto", "goal_step", "resection")
#: Angle (radians) between the heading and the landmark group after a failed measurement.
FALLBACK_OFFSET = math.radians(45)
#: Largest RMS bearing residual (radians) of an accepted resection (interim nest map).
MAX_RESECTION_RMS = math.radians(5)


@dataclass
class DistanceController(Controller):
    """Yu & Kim's homing loop from the ``panorama`` and ``goal`` observations.

    Each cycle: remember the view, step ``step_length`` m straight ahead (heading held, ψ =
    0), let the motors settle (``settle_moves`` creeping moves of ``settle_length`` m, so
    the view is taken at rest and the commanded step is the travelled one), take the
    second view, localise (Eq. 1, §II-B), then move towards the nest by the estimated
    distance, at most ``move_length`` m. The step length in Eq. 1 is the commanded one
    (forward travel of the planned actions), never odometry.

    Arrival (our choice, the paper has none; module doc): when the estimate puts the nest
    within ``move_length`` and agrees within ``confirm_tolerance`` m with the previous
    estimate carried forward by the moves commanded since (:func:`arrival_confirmed`),
    the robot drives the whole estimated distance home, unless the obstacle check
    diverts it, and then stops; a final approach shorter than ``arrive_tolerance`` is
    not driven (it stops on the spot).

    ``nest``: where the nest map comes from (module doc): ``"goal_step"`` needs the
    observation key ``goal_step`` taken ``nest_step`` m ahead of the nest; ``"resection"``
    the interim; ``"auto"`` the first if the key is present.

    Obstacles (our addition; the paper's robot drove among the cylinders without saying
    how it avoided them): every move, the probing step included, is checked against the
    landmarks of the current view (:func:`view_obstacles`: Eq. 1 distances where measured,
    else the distance implied by the arc's angular width and the landmark radius). A move
    whose path passes within ``clearance`` m (robot centre to cylinder surface) of one is
    turned to the nearest free direction (:func:`free_direction`). A measuring step that
    did not move the robot (no landmark shifted: it is pushing against something) is
    followed by a turn-around.
    """

    step_length: float = 0.15
    move_length: float = 0.3
    settle_moves: int = 2
    settle_length: float = 0.005
    arrive_tolerance: float = 0.05
    confirm_tolerance: float = 0.15
    nest: str = "auto"
    nest_step: float = 0.15
    assignments: str = "cyclic"
    min_axis_deg: float = 10.0
    min_parallax_deg: float = 0.3
    clearance: float = 0.22
    landmark_radius: float = 0.1075

    moves_home: ClassVar[bool] = False   # probing steps are not home directions

    def validate(self) -> None:
        for key in ("step_length", "move_length", "settle_length", "arrive_tolerance",
                    "confirm_tolerance", "nest_step", "clearance", "landmark_radius"):
            value = getattr(self, key)
            require_positive(f"distance: {key}", value, "metres")
        if not (isinstance(self.settle_moves, int) and self.settle_moves >= 0):
            raise ValueError(f"distance: settle_moves must be an integer >= 0, "
                             f"got {self.settle_moves!r}")
        if self.nest not in NEST_SOURCES:
            raise ValueError(f"distance: nest must be one of {NEST_SOURCES}, got {self.nest!r}")
        self.config = DistanceConfig(min_axis_deg=self.min_axis_deg,
                                     min_parallax_deg=self.min_parallax_deg,
                                     assignments=self.assignments)

    def on_reset(self) -> None:
        self._phase = "probe"
        self._view0: np.ndarray | None = None
        self._travel: list[Move] = []
        self._nest_sum: np.ndarray | None = None
        self._nest_count: np.ndarray | None = None
        self._nest_map: LandmarkMap | None = None
        self._turned = False
        self._radii: list[float] = []
        self.last_estimate: PoseEstimate | None = None
        self.last_diagnostics: Diagnostics | None = None
        # arrival: the last estimate, the moves commanded since it, and whether the move
        # under way is the final approach (stop once it is done)
        self._anchor: PoseEstimate | None = None
        self._since: list[Move] = []
        self._arriving = False

    def observation_keys(self) -> tuple[str, ...]:
        """``goal_step`` too unless the interim nest map is asked for (``nest="resection"``)."""
        if self.nest == "resection":
            return ("panorama", "goal")
        return ("panorama", "goal", "goal_step")

    def _commanded_step(self) -> float:
        """Forward travel (m) of the actions planned for the step and settle moves."""
        actions = [a for m in self._travel for a in self._helper.plan(m)]
        pose = integrate(actions, self.motion_spec)
        return float(math.hypot(pose[0], pose[1]))

    def decide(self, observation) -> Move | None:
        if self._arriving:
            return None             # the final approach is done: arrived
        move = self._decide(observation)
        if move is not None:
            self._since.append(move)
        return move

    def _motion_since_anchor(self) -> np.ndarray:
        """(dx, dy, dyaw) of the moves commanded since the last estimate (planned
        actions through the kinematic model, never odometry)."""
        travel = self._helper.travel            # planning again must not change it
        actions = [a for m in self._since for a in self._helper.plan(m)]
        self._helper.travel = travel
        return integrate(actions, self.motion_spec)

    def _decide(self, observation) -> Move | None:
        if self._phase == "probe":
            view = observation["panorama"]
            if not self._turned:
                # look before stepping: turn on the spot if the step would hit a landmark
                obstacles = view_obstacles(detect_landmarks(view, self.config.segmentation),
                                           None, self._radius())
                probe = self.step_length + self.settle_moves * self.settle_length
                free = free_direction(0.0, probe, obstacles, self.clearance)
                if free is None or abs(free) > 1e-6:
                    self._turned = True
                    return Move(math.pi if free is None else free, 0.0)
            self._turned = False
            self._view0 = view
            self._travel = [Move(0.0, self.step_length)]
            self._phase = "settle"
            return self._travel[0]
        if self._phase == "settle" and len(self._travel) <= self.settle_moves:
            move = Move(0.0, self.settle_length)
            self._travel.append(move)
            return move
        self._phase = "probe"
        step = self._commanded_step()
        view = observation["panorama"]
        seg = self.config.segmentation
        arcs1 = detect_landmarks(view, seg)
        ego = landmark_distances(detect_landmarks(self._view0, seg), arcs1, step, 0.0,
                                 self.config)
        self._learn_radii(ego)
        obstacles = view_obstacles(arcs1, ego, self._radius())
        if _blocked(ego):
            # the step did not move the robot: back away from whatever it pushes against
            return self._safe(math.pi, self.move_length / 2, obstacles)
        nest_map = self._nest(observation, self._view0, view, step)
        if nest_map is None:
            return self._fallback(arcs1, obstacles)
        pose, direction, diag = distance_homing(self._view0, view, step, nest_map, 0.0,
                                                self.config)
        self.last_diagnostics, self.last_estimate = diag, pose
        if pose is None:
            return self._fallback(arcs1, obstacles)
        self.last_home_direction = direction
        arrived = arrival_confirmed(self._anchor, self._motion_since_anchor(), pose,
                                    self.move_length, self.confirm_tolerance)
        self._anchor, self._since = pose, []
        if arrived:
            if pose.home_distance < self.arrive_tolerance:
                return None
            move = self._safe(direction, pose.home_distance, obstacles)
            # the final approach only if the obstacle check left it heading home
            self._arriving = (move.distance == pose.home_distance
                              and abs(wrap_angle(move.direction - direction)) < 1e-6)
            return move
        return self._safe(direction, min(self.move_length, pose.home_distance), obstacles)

    def _radius(self) -> float:
        """Landmark radius for width-based distances: the median of this episode's
        measured radii (R sin(w/2)), else the ``landmark_radius`` prior."""
        return float(np.median(self._radii)) if self._radii else self.landmark_radius

    def _learn_radii(self, ego: LandmarkMap) -> None:
        for r, w in zip(ego.distances, ego.widths):
            if np.isfinite(r) and 0 < w < math.radians(40):
                self._radii.append(float(r * math.sin(w / 2)))

    def _safe(self, direction: float, length: float, obstacles) -> Move:
        """``Move(direction, length)`` turned to the nearest direction whose path (and the
        next measuring step) keeps ``clearance`` from every seen landmark."""
        reach = length + self.step_length + self.settle_moves * self.settle_length
        free = free_direction(direction, reach, obstacles, self.clearance)
        if free is None:
            return Move(wrap_angle(direction + math.pi), 0.0)
        return Move(wrap_angle(free), length)

    def _fallback(self, arcs: Sequence[Arc], obstacles) -> Move:
        """Too few measurable landmarks (seen from the periphery they crowd into a narrow
        sector, merge or sit on the line of motion): turn so that the landmark group lies
        ``FALLBACK_OFFSET`` off the heading and walk one ``move_length`` that way (kept
        clear of the landmarks), so the next measurement is closer to the landmarks and
        off their axis (our addition; the paper leaves such places without a decision,
        Fig. 10)."""
        if not arcs:
            return self._safe(FALLBACK_OFFSET, self.move_length, obstacles)
        mean = math.atan2(sum(math.sin(a.bearing) for a in arcs),
                          sum(math.cos(a.bearing) for a in arcs))
        return self._safe(wrap_angle(mean + FALLBACK_OFFSET), self.move_length, obstacles)

    def _nest(self, observation, view0, view1, step: float) -> LandmarkMap | None:
        """The nest map: measured from ``goal_step`` (paper) or the resection interim."""
        seg = self.config.segmentation
        use_step = self.nest == "goal_step" or (self.nest == "auto" and "goal_step" in observation)
        if use_step:
            if "goal_step" not in observation:
                raise ValueError("distance: nest='goal_step' needs the observation key "
                                 "'goal_step' (second nest snapshot)")
            if self._nest_map is None:
                self._nest_map = build_nest_map(observation["goal"], observation["goal_step"],
                                                self.nest_step, 0.0, self.config)
            return self._nest_map
        ego = landmark_distances(detect_landmarks(view0, seg), detect_landmarks(view1, seg),
                                 step, 0.0, self.config)
        goal_arcs = detect_landmarks(observation["goal"], seg)
        # the resection is our interim, not the paper's step: it tries every assignment
        estimate, rms = resect_nest_map(ego, np.array([a.bearing for a in goal_arcs]), "all")
        if estimate is not None and rms <= MAX_RESECTION_RMS:
            pos = np.nan_to_num(estimate.positions)
            ok = estimate.valid.astype(float)
            if self._nest_sum is None or self._nest_sum.shape[0] != len(estimate):
                self._nest_sum, self._nest_count = np.zeros_like(pos), np.zeros(len(estimate))
            self._nest_sum += pos * ok[:, None]
            self._nest_count += ok
        if self._nest_sum is None or np.count_nonzero(self._nest_count) < 2:
            return self._nest_map
        mean = self._nest_sum / np.maximum(self._nest_count, 1)[:, None]
        known = self._nest_count > 0
        bearings = np.array([a.bearing for a in goal_arcs])
        dist = np.where(known, np.hypot(mean[:, 0], mean[:, 1]), np.nan)
        self._nest_map = LandmarkMap(bearings, dist, np.zeros(len(bearings)),
                                     tuple("ok" if k else "unmeasured" for k in known))
        return self._nest_map
