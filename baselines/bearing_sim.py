"""Pure 2-D simulator of the bearing-only laws of :mod:`homing_baselines.bearing_laws` (the
simulator of Bekris, Argyros & Kavraki §5 "Verifying the local control laws", used for
their Fig. 4 and Fig. 8).

Landmarks are points on the plane, the robot a point (§2: "the robot is abstracted as a
point on the 2D plane") that measures ideal bearings (``atan2``, world frame, radians
CCW) and moves a fixed ``step`` (metres) along the unit motion vector until the stop test
(:func:`~homing_baselines.bearing_laws.snapshots_similar`) holds or ``max_steps`` have passed.
A run succeeds when it ends within ``success_radius`` of the goal.

Everything is batched over robots so that a reachability map (one run per grid point)
takes seconds: :func:`simulate_batch`, :func:`reachability_map`; :func:`simulate` is one
run with its trajectory.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Literal

import numpy as np

from homing_gym.validation import require_positive

from homing_baselines.bearing_laws import (DEFAULT_STOP_TOL, LAWS, UnifiedBatch, UnifiedConfig,
                                    motion_vectors, snapshots_similar)


@dataclass(frozen=True)
class SimConfig:
    """Simulator settings. ``step``: distance moved per iteration (m); ``max_steps``:
    iteration budget; ``stop_tol``: stop-test tolerance (rad, on angular separations);
    ``success_radius``: largest final distance to the goal that counts as reached (m);
    ``unified``: the unified law's tolerances."""

    step: float = 0.01
    max_steps: int = 3000
    stop_tol: float = DEFAULT_STOP_TOL
    success_radius: float = 0.1
    unified: UnifiedConfig = UnifiedConfig()

    def __post_init__(self) -> None:
        for name in ("step", "stop_tol", "success_radius"):
            value = getattr(self, name)
            require_positive(f"SimConfig.{name}", value)
        if int(self.max_steps) != self.max_steps or self.max_steps < 1:
            raise ValueError(f"SimConfig.max_steps must be a positive integer, got {self.max_steps!r}")


@dataclass(frozen=True)
class SimResult:
    """One run: ``trajectory`` ``(T + 1, 2)`` positions (m) from the start, ``success``
    (ended within ``success_radius``), ``stopped`` (the stop test held), ``final_error``
    (m), ``steps`` taken, ``states`` ``(T,)`` the unified law's state at each step (all 0
    for the other laws)."""

    trajectory: np.ndarray
    success: bool
    stopped: bool
    final_error: float
    steps: int
    states: np.ndarray


@dataclass(frozen=True)
class BatchResult:
    """``B`` runs: ``final`` ``(B, 2)`` positions, ``success``, ``stopped`` ``(B,)``,
    ``final_error`` ``(B,)`` (m), ``steps`` ``(B,)``, ``states`` ``(B,)`` the unified law's
    final state (0 for the other laws)."""

    final: np.ndarray
    success: np.ndarray
    stopped: np.ndarray
    final_error: np.ndarray
    steps: np.ndarray
    states: np.ndarray


def _landmarks(landmarks) -> np.ndarray:
    lm = np.asarray(landmarks, dtype=np.float64)
    if lm.ndim != 2 or lm.shape[1] != 2:
        raise ValueError(f"landmarks must have shape (N, 2), got {lm.shape}")
    if lm.shape[0] < 3:
        raise ValueError(f"landmarks: need at least 3, got {lm.shape[0]}")
    if not np.all(np.isfinite(lm)):
        raise ValueError(f"landmarks contain a non-finite value: {lm.tolist()}")
    return lm


def _points(name: str, pts, shape_hint: str) -> np.ndarray:
    arr = np.asarray(pts, dtype=np.float64)
    if arr.ndim == 1:
        arr = arr[None]
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"{name} must have shape {shape_hint}, got {np.shape(pts)}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} contain a non-finite value")
    return arr


def bearings(landmarks, positions) -> np.ndarray:
    """Ideal bearings (radians, CCW from +x, world frame) of the landmarks ``(N, 2)``
    seen from ``positions`` ``(..., 2)``: shape ``(..., N)``."""
    lm = np.asarray(landmarks, dtype=np.float64)
    p = np.asarray(positions, dtype=np.float64)[..., None, :]
    d = lm - p
    return np.arctan2(d[..., 1], d[..., 0])


def _run(lm: np.ndarray, starts: np.ndarray, goals: np.ndarray, law: str, cfg: SimConfig,
         record: bool, progress: Callable[[int], None] | None = None):
    if law not in LAWS:
        raise ValueError(f"unknown law {law!r}; choose one of {LAWS}")
    b = starts.shape[0]
    pos = starts.copy()
    goal_b = bearings(lm, goals)
    active = np.ones(b, dtype=bool)
    stopped = np.zeros(b, dtype=bool)
    steps = np.zeros(b, dtype=np.int64)
    unified = UnifiedBatch(cfg.unified) if law == "unified" else None
    states = np.zeros(b, dtype=np.int8)
    traj = [pos.copy()] if record else None
    state_log = [] if record else None
    for _ in range(cfg.max_steps):
        cur_b = bearings(lm, pos)
        sim = snapshots_similar(cur_b, goal_b, cfg.stop_tol)
        newly = active & sim
        stopped |= newly
        active &= ~sim
        if not active.any():
            break
        if unified is not None:
            # The state machine runs for every robot (stopped ones do not move).
            m = unified.step(cur_b, goal_b)
            states = unified.status.copy()
        else:
            m = motion_vectors(cur_b, goal_b, complementary=(law == "complementary"))
        norm = np.hypot(m[:, 0], m[:, 1])
        move = active & (norm > 0)
        unit = m / np.where(norm > 0, norm, 1.0)[:, None]
        pos = np.where(move[:, None], pos + cfg.step * unit, pos)
        steps += active
        if record:
            traj.append(pos.copy())
            state_log.append(states.copy())
        if progress is not None:
            progress(1)
    err = np.hypot(*(pos - goals).T)
    success = err <= cfg.success_radius
    return pos, success, stopped, err, steps, states, traj, state_log


def simulate(landmarks, start, goal, law: str = "unified",
             config: SimConfig | None = None) -> SimResult:
    """Run ``law`` (``"basic"``, ``"complementary"`` or ``"unified"``) from ``start`` to
    ``goal`` (m) among ``landmarks`` ``(N, 2)`` and return the trajectory."""
    cfg = config or SimConfig()
    lm = _landmarks(landmarks)
    s = _points("start", start, "(2,)")
    g = _points("goal", goal, "(2,)")
    if s.shape[0] != 1 or g.shape[0] != 1:
        raise ValueError("simulate() runs one start and one goal; use simulate_batch()")
    pos, success, stopped, err, steps, _, traj, state_log = _run(lm, s, g, law, cfg, record=True)
    states = (np.array([s_[0] for s_ in state_log], dtype=np.int8) if state_log
              else np.zeros(0, dtype=np.int8))
    return SimResult(trajectory=np.array([t[0] for t in traj]), success=bool(success[0]),
                     stopped=bool(stopped[0]), final_error=float(err[0]),
                     steps=int(steps[0]), states=states)


def simulate_batch(landmarks, starts, goals, law: str = "unified",
                   config: SimConfig | None = None,
                   progress: Callable[[int], None] | None = None) -> BatchResult:
    """``B`` independent runs of ``law`` from ``starts`` ``(B, 2)`` to ``goals`` ``(B, 2)``
    (either may be one ``(2,)`` point, broadcast). ``progress(k)`` is called after each
    iteration (e.g. ``tqdm.update``)."""
    cfg = config or SimConfig()
    lm = _landmarks(landmarks)
    s = _points("starts", starts, "(B, 2)")
    g = _points("goals", goals, "(B, 2)")
    b = max(s.shape[0], g.shape[0])
    if s.shape[0] not in (1, b) or g.shape[0] not in (1, b):
        raise ValueError(f"starts ({s.shape[0]}) and goals ({g.shape[0]}) do not broadcast")
    s = np.broadcast_to(s, (b, 2)).copy()
    g = np.broadcast_to(g, (b, 2)).copy()
    pos, success, stopped, err, steps, states, _, _ = _run(lm, s, g, law, cfg, record=False,
                                                           progress=progress)
    return BatchResult(final=pos, success=success, stopped=stopped, final_error=err,
                       steps=steps, states=states)


@dataclass(frozen=True)
class ReachabilityMap:
    """Reachability on a grid: ``reached[r, c]`` is whether the run for grid point
    ``(xs[c], ys[r])`` succeeded; ``vary`` says whether the grid points are goals (fixed
    ``start``, the paper's Fig. 4) or starts (fixed ``goal``); ``valid`` is False where the
    point is too close to a landmark to run (``reached`` is False there)."""

    law: str
    vary: str
    xs: np.ndarray
    ys: np.ndarray
    reached: np.ndarray
    valid: np.ndarray
    landmarks: np.ndarray
    start: np.ndarray | None
    goal: np.ndarray | None

    @property
    def fraction(self) -> float:
        """Fraction of the valid grid points that were reached."""
        return float(self.reached[self.valid].mean()) if self.valid.any() else math.nan


def reachability_map(landmarks, law: str, xs, ys, *, start=None, goal=None,
                     config: SimConfig | None = None, min_clearance: float = 0.05,
                     progress: Callable[[int], None] | None = None) -> ReachabilityMap:
    """Which grid points ``(x, y)`` for ``x`` in ``xs``, ``y`` in ``ys`` (m) ``law`` reaches.

    Give exactly one of ``start`` (the grid points are goals: the paper's Fig. 4, "every
    point is painted gray if it constitutes a reachable destination") or ``goal`` (the
    grid points are starts: which starts converge to this goal). Points within
    ``min_clearance`` (m) of a landmark are skipped (``valid`` False).
    """
    if (start is None) == (goal is None):
        raise ValueError("give exactly one of start= (grid of goals) or goal= (grid of starts)")
    lm = _landmarks(landmarks)
    xs = np.asarray(xs, dtype=np.float64)
    ys = np.asarray(ys, dtype=np.float64)
    gx, gy = np.meshgrid(xs, ys)
    pts = np.stack([gx.ravel(), gy.ravel()], axis=1)
    dist = np.hypot(pts[:, None, 0] - lm[None, :, 0], pts[:, None, 1] - lm[None, :, 1]).min(axis=1)
    fixed = _points("start" if start is not None else "goal",
                    start if start is not None else goal, "(2,)")[0]
    valid = dist > min_clearance
    if start is not None:
        res = simulate_batch(lm, fixed, pts[valid], law, config, progress)
    else:
        res = simulate_batch(lm, pts[valid], fixed, law, config, progress)
    reached = np.zeros(pts.shape[0], dtype=bool)
    reached[valid] = res.success
    vary: Literal["goal", "start"] = "goal" if start is not None else "start"
    return ReachabilityMap(law=law, vary=vary, xs=xs, ys=ys,
                           reached=reached.reshape(gy.shape), valid=valid.reshape(gy.shape),
                           landmarks=lm, start=None if start is None else fixed,
                           goal=None if goal is None else fixed)


# ---------------------------------------------------------------------------------------
# The regions of §2 (ground truth for figures and tests; the laws never see positions)
# ---------------------------------------------------------------------------------------

def circumcircle(landmarks) -> tuple[np.ndarray, float]:
    """Centre (m) and radius (m) of the circle through the first three landmarks."""
    a, b, c = _landmarks(landmarks)[:3]
    d = 2 * (a[0] * (b[1] - c[1]) + b[0] * (c[1] - a[1]) + c[0] * (a[1] - b[1]))
    if abs(d) < 1e-12:
        raise ValueError("landmarks are collinear: no circumscribed circle")
    sa, sb, sc = a @ a, b @ b, c @ c
    ux = (sa * (b[1] - c[1]) + sb * (c[1] - a[1]) + sc * (a[1] - b[1])) / d
    uy = (sa * (c[0] - b[0]) + sb * (a[0] - c[0]) + sc * (b[0] - a[0])) / d
    centre = np.array([ux, uy])
    return centre, float(np.hypot(*(a - centre)))


def _side(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Sign of the cross product (b - a) x (p - a): which side of line a-b."""
    return np.sign((b[0] - a[0]) * (p[..., 1] - a[1]) - (b[1] - a[1]) * (p[..., 0] - a[0]))


def region(landmarks, points) -> np.ndarray:
    """Region of §2 / Fig. 9b of each point ``(..., 2)`` for a landmark triangle, as a
    string array: ``"T"`` (inside the triangle T^), ``"C-T"`` (inside the circle C^, not in
    T^), ``"H"`` (H^: some H_j, the vertical angle at vertex L_j between the extensions
    of the two sides through it) or ``"rest"``."""
    lm = _landmarks(landmarks)[:3]
    p = np.asarray(points, dtype=np.float64)
    centre, radius = circumcircle(lm)
    out = np.full(p.shape[:-1], "rest", dtype=object)
    in_c = np.hypot(p[..., 0] - centre[0], p[..., 1] - centre[1]) < radius
    in_h = np.zeros(p.shape[:-1], dtype=bool)
    in_t = np.ones(p.shape[:-1], dtype=bool)
    for j in range(3):
        i, k = (j + 1) % 3, (j + 2) % 3
        # H_j: beyond line L_i L_j from L_k, and beyond line L_j L_k from L_i.
        far_ij = _side(p, lm[i], lm[j]) == -_side(lm[k], lm[i], lm[j])
        far_jk = _side(p, lm[j], lm[k]) == -_side(lm[i], lm[j], lm[k])
        in_h |= far_ij & far_jk
        in_t &= _side(p, lm[i], lm[j]) == _side(lm[k], lm[i], lm[j])
    out[in_h] = "H"
    out[in_c & ~in_t & ~in_h] = "C-T"
    out[in_t] = "T"
    return out


__all__ = ["BatchResult", "ReachabilityMap", "SimConfig", "SimResult", "bearings",
           "circumcircle", "reachability_map", "region", "simulate", "simulate_batch"]
