"""Bearing-only homing control laws of Bekris, Argyros & Kavraki (§2 of "Exploiting
panoramic vision for bearing-only robot homing"): the basic law (Eq. 1-2), the
complementary law and the unified law (Algorithm 1), as pure numpy functions.

Inputs are two *snapshots* (§2): the bearings (radians, counter-clockwise) of the same
``N >= 3`` identified landmarks seen from the current position ``A`` and from the goal
``T``; index ``i`` of both arrays must be the same landmark ``L_i``.

Frames, and what the caller must provide
----------------------------------------
The laws only use *angular separations* ``theta_ij`` (differences of bearings inside one
snapshot), and the bisector of ``L_i A L_j`` measured in the current snapshot, so

* the bearings of one snapshot must share one frame (all measured from the same heading);
* the two snapshots do **not** need a common frame: the paper's law is compass-free
  (abstract, §7), and rotating all goal bearings by a constant changes nothing;
* the motion vector is returned in the frame of the *current* bearings (the robot frame,
  e.g. counter-clockwise from the heading as in :mod:`homing_gym.render.panorama`).

A caller whose snapshots are aligned (a compass, or the 2-D simulator's world frame) can
of course use them as is; only :func:`snapshots_similar` with ``aligned=True`` needs that.

Definitions (our notation for the paper's)
------------------------------------------
* Pairs: all unordered pairs ``(i, j)``, ``i < j`` (:func:`landmark_pairs`); Eq. 2 writes
  the three pairs of three landmarks, "a partial motion vector M_ij is then defined for
  each possible pair" (§2) gives all ``N(N-1)/2`` for more landmarks.
* ``theta_ij = (beta_j - beta_i) mod 2*pi`` in ``[0, 2*pi)``: the angle swept
  counter-clockwise from ``L_i`` to ``L_j`` (§2: "angular separations theta_ij, theta'_ij in
  [0, 2 pi)"); ``theta'_ij`` the same at the goal; ``Delta theta_ij = theta'_ij - theta_ij``.
* ``delta_ij``: the unit vector along ``beta_i + theta_ij / 2``, the bisector of the swept
  angle (Fig. 2): the interior bisector when ``theta_ij <= pi``, and the bisector of the
  reflex angle (pointing away from the landmarks) when ``theta_ij > pi``; moving along it
  increases ``theta_ij`` in both cases, as §2 requires.
* Eq. 1: ``M_ij = g(Delta theta_ij) delta_ij`` with ``g(d) = d`` for ``|d| <= pi``,
  ``2 pi - d`` for ``d > pi``, ``-2 pi - d`` for ``d < -pi``. ``M_ij`` does not depend on
  the order of the pair (``delta_ji = -delta_ij`` and ``g`` is odd), and is continuous
  when the robot crosses the line ``L_i L_j`` outside the segment, where ``theta_ij``
  jumps between 0 and ``2 pi`` (this is why Eq. 1 folds ``Delta theta`` that way).
* The nearest landmark pair (NLP, §2 "Complementary control law") is the pair of smallest
  pi-difference ``|pi - theta'_ij|`` *at the goal* (the paper: "the nearest landmark pair
  to the goal"); its ``M_ij`` is the nearest motion vector (NMV). Taking it from the goal
  snapshot keeps it fixed during a run; ties go to the first pair in
  :func:`landmark_pairs` order.

Choices where the paper is ambiguous are listed on :class:`UnifiedLaw` and in
``docs/bearing.md``.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

TWO_PI = 2.0 * math.pi

#: Default stop tolerance (radians) on every angular separation: Algorithm 1 stops "when
#: current snapshot A and goal snapshot T are similar". 0.005 rad (0.29 deg) suits ideal
#: bearings (the 2-D simulator); from real panoramas use about the measurement accuracy
#: of a separation, which §6 puts at 0.027 rad for a 1394-pixel panorama and 3-pixel error.
DEFAULT_STOP_TOL = 0.005

LAWS: tuple[str, ...] = ("basic", "complementary", "unified")


class UnifiedState(enum.IntEnum):
    """The three states of Algorithm 1."""

    UNCERTAIN = 0
    BASIC = 1
    COMPLEMENTARY = 2


class Criterion(enum.IntEnum):
    """Which geometric criterion of §2 ("The unification of the two local control laws")
    set the state of the unified law (``NONE`` while it is UNCERTAIN)."""

    NONE = 0
    GOAL_IN_TRIANGLE = 1        # criterion 1: T in T^
    GOAL_IN_H = 2               # criterion 2: T in H^ and A in T^
    LAST_CIRCLE_ON_EXIT = 3     # criterion 3: last landmark-goal circle before leaving T^
    NLP_CIRCLE_TREND = 4        # criterion 4: non-NLP differences on the NLP circle


@dataclass(frozen=True)
class LawResult:
    """One evaluation of a control law.

    ``vector``: the motion vector ``M`` (Eq. 2, or the complementary/unified variant) in
    the frame of the current bearings; its length is in radians (Eq. 1 scales unit
    bisectors by angle differences), so only its direction is a command.
    ``direction``: ``atan2`` of ``vector`` (radians, counter-clockwise in the current
    frame), NaN when ``M = 0``. ``pair_vectors``: the ``(P, 2)`` components ``M_ij``
    *as summed* (the complementary law's inverted ones already negated). ``pairs``: the
    ``(i, j)`` of each row. ``theta``, ``theta_goal``, ``delta_theta``: ``(P,)`` separations
    at ``A``, at ``T`` and their difference (radians). ``nlp``: row of the nearest
    landmark pair. ``similar``: the stop test :func:`snapshots_similar` on separations
    (default tolerance; the unified law's ``UnifiedConfig.stop_tol``). ``state`` and ``criterion``: the unified law's state after
    this step and the criterion that set it (``None`` for the other laws).
    """

    vector: np.ndarray
    direction: float
    pair_vectors: np.ndarray
    pairs: tuple[tuple[int, int], ...]
    theta: np.ndarray
    theta_goal: np.ndarray
    delta_theta: np.ndarray
    nlp: int
    similar: bool
    state: UnifiedState | None = None
    criterion: Criterion | None = None

    @property
    def unit(self) -> np.ndarray:
        """``vector`` normalised to length 1 (zeros when ``M = 0``)."""
        norm = float(np.hypot(*self.vector))
        return self.vector / norm if norm > 0 else np.zeros(2)


# ---------------------------------------------------------------------------------------
# Input checks and geometry of snapshots (batched over leading axes)
# ---------------------------------------------------------------------------------------

def check_bearings(current, goal) -> tuple[np.ndarray, np.ndarray]:
    """Float arrays of the two snapshots, shape ``(..., N)``; ``ValueError`` naming the
    bad value when ``N < 3``, the shapes differ, or a bearing is not finite."""
    cur = np.asarray(current, dtype=np.float64)
    tgt = np.asarray(goal, dtype=np.float64)
    for name, arr in (("current", cur), ("goal", tgt)):
        if arr.ndim == 0:
            raise ValueError(f"{name} bearings must be an array of N >= 3 angles, got a scalar")
        if arr.shape[-1] < 3:
            raise ValueError(f"{name} bearings: need at least 3 landmarks, got {arr.shape[-1]}")
    if cur.shape != tgt.shape:
        raise ValueError(f"current bearings have shape {cur.shape} but goal bearings have "
                         f"shape {tgt.shape}; both must list the same landmarks")
    for name, arr in (("current", cur), ("goal", tgt)):
        bad = np.argwhere(~np.isfinite(arr))
        if bad.size:
            idx = tuple(int(v) for v in bad[0])
            raise ValueError(f"{name} bearings{list(idx)} is {float(arr[idx])!r}; "
                             "bearings must be finite")
    return cur, tgt


def landmark_pairs(n: int) -> tuple[tuple[int, int], ...]:
    """All unordered pairs ``(i, j)``, ``i < j``, of ``n`` landmarks, in lexicographic order."""
    return tuple((i, j) for i in range(n) for j in range(i + 1, n))


def _pair_index(n: int) -> tuple[np.ndarray, np.ndarray]:
    pairs = landmark_pairs(n)
    return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])


def angular_separations(bearings) -> np.ndarray:
    """``theta_ij = (beta_j - beta_i) mod 2 pi`` in ``[0, 2 pi)`` for every pair of
    :func:`landmark_pairs` (radians), shape ``(..., P)``."""
    b = np.asarray(bearings, dtype=np.float64)
    i, j = _pair_index(b.shape[-1])
    return np.mod(b[..., j] - b[..., i], TWO_PI)


def eq1_gain(delta_theta) -> np.ndarray:
    """The scalar factor of Eq. 1 for ``Delta theta_ij`` in ``(-2 pi, 2 pi)`` (radians):
    ``d`` if ``|d| <= pi``, ``2 pi - d`` if ``d > pi``, ``-2 pi - d`` if ``d < -pi``."""
    d = np.asarray(delta_theta, dtype=np.float64)
    return np.where(d > math.pi, TWO_PI - d, np.where(d < -math.pi, -TWO_PI - d, d))


def max_gap(bearings) -> np.ndarray:
    """Largest angle (radians) between bearings consecutive counter-clockwise, ``(...)``.

    Criterion 1 of §2: a position sees the landmarks with every consecutive separation
    below ``pi`` iff it is inside their triangle ``T^`` (convex hull for ``N > 3``).
    """
    b = np.sort(np.mod(np.asarray(bearings, dtype=np.float64), TWO_PI), axis=-1)
    gaps = np.diff(b, axis=-1)
    wrap = TWO_PI - (b[..., -1] - b[..., 0])
    return np.maximum(gaps.max(axis=-1), wrap)


def inside_triangle(bearings) -> np.ndarray:
    """Criterion 1 (§2): ``theta_ij < pi`` for all landmarks consecutive as seen from the
    snapshot, i.e. the snapshot was taken inside ``T^``. Boolean, shape ``(...)``."""
    return max_gap(bearings) < math.pi


def cyclic_order(bearings) -> np.ndarray:
    """Rank of each landmark counter-clockwise from landmark 0 (ints, ``(..., N)``); two
    snapshots see the landmarks in the same cyclic order iff their ranks are equal."""
    b = np.asarray(bearings, dtype=np.float64)
    rel = np.mod(b - b[..., :1], TWO_PI)
    return np.argsort(np.argsort(rel, axis=-1, kind="stable"), axis=-1, kind="stable")


def nearest_landmark_pair(goal) -> np.ndarray | int:
    """Row (in :func:`landmark_pairs`) of the NLP: smallest pi-difference
    ``|pi - theta'_ij|`` of the goal snapshot (§2). ``int`` for one snapshot."""
    theta_goal = angular_separations(goal)
    nlp = np.argmin(np.abs(math.pi - theta_goal), axis=-1)
    return int(nlp) if np.ndim(nlp) == 0 else nlp


def snapshots_similar(current, goal, tol: float = DEFAULT_STOP_TOL, *,
                      aligned: bool = False) -> bool | np.ndarray:
    """Stop test of Algorithm 1 ("until current snapshot A and goal snapshot T are similar").

    ``aligned=False`` (default, compass-free like the laws): every angular separation
    agrees, ``max_ij |wrap(theta'_ij - theta_ij)| <= tol`` (radians, ``wrap`` into
    ``(-pi, pi]``); equivalently the two bearing sets agree up to one common rotation.
    ``aligned=True``: the snapshots share a frame and every bearing agrees,
    ``max_i |wrap(beta'_i - beta_i)| <= tol``.
    With three landmarks in general position the separations fix the position, so this
    test is only met near the goal (the paper's §6 discusses the size of that region).
    """
    cur, tgt = check_bearings(current, goal)
    if aligned:
        diff = tgt - cur
    else:
        diff = angular_separations(tgt) - angular_separations(cur)
    err = np.abs(np.mod(diff + math.pi, TWO_PI) - math.pi).max(axis=-1)
    out = err <= tol
    return bool(out) if np.ndim(out) == 0 else out


# ---------------------------------------------------------------------------------------
# Basic and complementary laws
# ---------------------------------------------------------------------------------------

@dataclass(frozen=True)
class _Terms:
    theta: np.ndarray          # (..., P)
    theta_goal: np.ndarray     # (..., P)
    delta: np.ndarray          # (..., P)
    pair_vectors: np.ndarray   # (..., P, 2) M_ij of Eq. 1
    nlp: np.ndarray            # (...) int


def _terms(cur: np.ndarray, tgt: np.ndarray) -> _Terms:
    i, _ = _pair_index(cur.shape[-1])
    theta = angular_separations(cur)
    theta_goal = angular_separations(tgt)
    delta = theta_goal - theta
    bisector = cur[..., i] + 0.5 * theta                       # direction of delta_ij
    gain = eq1_gain(delta)
    vecs = np.stack([gain * np.cos(bisector), gain * np.sin(bisector)], axis=-1)
    nlp = np.argmin(np.abs(math.pi - theta_goal), axis=-1)
    return _Terms(theta, theta_goal, delta, vecs, nlp)


def _signs(nlp: np.ndarray, n_pairs: int, invert_non_nlp) -> np.ndarray:
    """+1 for the NMV, -1 for the other pairs where ``invert_non_nlp`` (else +1)."""
    is_nlp = np.arange(n_pairs) == np.asarray(nlp)[..., None]
    inv = np.asarray(invert_non_nlp, dtype=bool)[..., None]
    return np.where(is_nlp | ~inv, 1.0, -1.0)


def motion_vectors(current, goal, complementary=False) -> np.ndarray:
    """Batched motion vectors ``M`` (shape ``(..., 2)``, current frame) of the basic law
    (Eq. 2, ``complementary=False``) or the complementary law (``True``); ``complementary``
    may be a boolean array over the leading axes to mix the two per row."""
    cur, tgt = check_bearings(current, goal)
    t = _terms(cur, tgt)
    signs = _signs(t.nlp, t.theta.shape[-1], complementary)
    return (signs[..., None] * t.pair_vectors).sum(axis=-2)


def _result(cur: np.ndarray, tgt: np.ndarray, complementary: bool,
            state: UnifiedState | None = None, criterion: Criterion | None = None,
            stop_tol: float = DEFAULT_STOP_TOL) -> LawResult:
    t = _terms(cur, tgt)
    signs = _signs(t.nlp, t.theta.shape[-1], complementary)
    comps = signs[:, None] * t.pair_vectors
    vec = comps.sum(axis=0)
    direction = math.atan2(vec[1], vec[0]) if np.any(vec != 0) else math.nan
    return LawResult(vector=vec, direction=direction, pair_vectors=comps,
                     pairs=landmark_pairs(cur.shape[-1]), theta=t.theta,
                     theta_goal=t.theta_goal, delta_theta=t.delta, nlp=int(t.nlp),
                     similar=bool(snapshots_similar(cur, tgt, stop_tol)), state=state,
                     criterion=criterion)


def _single(current, goal) -> tuple[np.ndarray, np.ndarray]:
    cur, tgt = check_bearings(current, goal)
    if cur.ndim != 1:
        raise ValueError(f"bearings must be 1-D (one snapshot), got shape {cur.shape}; "
                         "use motion_vectors() for batches")
    return cur, tgt


def basic_law(current, goal) -> LawResult:
    """Basic control law (§2, Eq. 1-2): ``M = sum over pairs of M_ij`` with
    ``M_ij = g(Delta theta_ij) delta_ij`` (Eq. 1, Fig. 2-3).

    ``current``, ``goal``: bearings (radians, CCW) of the same ``N >= 3`` landmarks at
    ``A`` and ``T``. Reaches every goal in the interior ``C^`` of the landmarks' circle and
    in ``H^`` whatever the start (§2, Fig. 4a).
    """
    cur, tgt = _single(current, goal)
    return _result(cur, tgt, complementary=False)


def complementary_law(current, goal) -> LawResult:
    """Complementary control law (§2): Eq. 2 with every component that is not the NMV
    inverted, ``M = M_NLP - sum_{(i,j) != NLP} M_ij``. For three landmarks this is the
    paper's "the two component motion vectors that are not the NMV vectors should be
    inverted"; for more we invert all non-NLP components. Reaches the complement of the
    basic law's set (Fig. 4b).
    """
    cur, tgt = _single(current, goal)
    return _result(cur, tgt, complementary=True)


# ---------------------------------------------------------------------------------------
# Unified law (Algorithm 1)
# ---------------------------------------------------------------------------------------

@dataclass(frozen=True)
class UnifiedConfig:
    """Settings of the unified law's criteria 3 and 4 (angles in radians; see
    :class:`UnifiedLaw` for how they are used).

    ``circle_tol``: ``A`` has *reached* the NLP arc ``(L_i T L_j)`` (criterion 4) when
    ``|Delta theta_NLP| <= circle_tol`` or ``Delta theta_NLP`` changed sign inside the band.
    ``arc_band``: it stays *on* the arc while ``|Delta theta_NLP| <= arc_band``.
    ``dwell``: criterion 4 is judged once ``A`` has been on the arc for this many
    consecutive steps since reaching it (20 steps = 20 cm at the simulator's 1 cm step).
    ``trend_steps``: "increasing"/"decreasing" compare each non-NLP ``|g(Delta theta_ij)|``
    with its value this many steps earlier. ``goal_margin``: criterion 4 is not judged
    when every ``|g(Delta theta_ij)|`` is at most this (next to ``T``, which lies on every
    landmark-goal circle). ``no_crossing``: criterion 3's decision when the robot leaves
    ``T^`` without having crossed any landmark-goal circle: ``"uncertain"`` (default: no
    information, stay UNCERTAIN) or ``"basic"`` (Algorithm 1's literal ``else``).
    ``stop_tol``: the stop test, see :func:`snapshots_similar`. ``trend_from``:
    ``"window"`` compares with ``trend_steps`` steps earlier; ``"arrival"`` with the
    values when ``A`` reached the arc (the change accumulates as the robot slides along
    it, where a short window of a robot that steps back and forth reads the phase of its
    steps). ``trend_margin``: a change counts only beyond this (radians; measurement noise).
    """

    circle_tol: float = 0.01
    arc_band: float = 0.1
    dwell: int = 20
    trend_steps: int = 5
    goal_margin: float = 0.05
    no_crossing: Literal["uncertain", "basic"] = "uncertain"
    stop_tol: float = DEFAULT_STOP_TOL
    trend_from: Literal["window", "arrival"] = "window"
    trend_margin: float = 0.0

    def __post_init__(self) -> None:
        if self.trend_from not in ("window", "arrival"):
            raise ValueError(f"UnifiedConfig.trend_from must be 'window' or 'arrival', "
                             f"got {self.trend_from!r}")
        for name in ("circle_tol", "arc_band", "goal_margin", "stop_tol", "trend_margin"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"UnifiedConfig.{name} must be finite and >= 0, got {value!r}")
        for name in ("dwell", "trend_steps"):
            value = getattr(self, name)
            if int(value) != value or value < 1:
                raise ValueError(f"UnifiedConfig.{name} must be an integer >= 1, got {value!r}")
        if self.no_crossing not in ("uncertain", "basic"):
            raise ValueError(f"UnifiedConfig.no_crossing must be 'uncertain' or 'basic', "
                             f"got {self.no_crossing!r}")


@dataclass
class UnifiedBatch:
    """Algorithm 1 for ``B`` independent robots at once (the 2-D simulator's reachability
    maps use it); :class:`UnifiedLaw` is the one-robot interface and documents the
    criteria. Arrays are ``(B, ...)``; the state starts on the first :meth:`step`; make a
    new object for a new run or goal."""

    config: UnifiedConfig = field(default_factory=UnifiedConfig)
    status: np.ndarray | None = None       # (B,) UnifiedState values
    criterion: np.ndarray | None = None    # (B,) Criterion values
    last_circle: np.ndarray | None = None  # (B,) pair row of the last circle crossed, -1 none
    on_arc_steps: np.ndarray | None = None  # (B,) consecutive steps on the NLP arc
    _prev_sin: np.ndarray | None = None    # (B, P) sin(Delta theta) at the previous step
    _prev_in_t: np.ndarray | None = None   # (B,) A in T^ at the previous step
    _prev_armed: np.ndarray | None = None  # (B,) criterion 3's condition at the previous step
    _prev_d_nlp: np.ndarray | None = None  # (B,) Delta theta_NLP at the previous step
    _arrival: np.ndarray | None = None     # (B, P) |g(Delta theta)| when A reached the arc
    _gains: list = field(default_factory=list)  # last (B, P) |g(Delta theta)|

    def step(self, current, goal) -> np.ndarray:
        """Update the states from the snapshots ``(B, N)`` and return the motion vectors
        ``(B, 2)`` (current frame) of this iteration of Algorithm 1."""
        cur, tgt = check_bearings(current, goal)
        if cur.ndim != 2:
            raise ValueError(f"UnifiedBatch.step wants (B, N) bearings, got shape {cur.shape}")
        cfg = self.config
        t = _terms(cur, tgt)
        b, n_pairs = t.theta.shape
        rows = np.arange(b)
        if self.status is None:
            self.status = np.zeros(b, dtype=np.int8)
            self.criterion = np.zeros(b, dtype=np.int8)
            self.last_circle = np.full(b, -1, dtype=np.int64)
            self.on_arc_steps = np.zeros(b, dtype=np.int64)
        elif self.status.shape != (b,):
            raise ValueError(f"batch size changed from {self.status.shape[0]} to {b}")

        # Landmark-goal circles crossed during the last step (criterion 3). The circle
        # through L_i, L_j and T is where the oriented angle L_i A L_j equals the goal's
        # modulo pi (inscribed angle theorem), i.e. where sin(Delta theta_ij) = 0.
        sin_d = np.sin(t.delta)
        if self._prev_sin is not None:
            crossed = (self._prev_sin * sin_d < 0) | ((self._prev_sin != 0) & (sin_d == 0))
            # Several circles in one step: the last is the one crossed latest along the
            # step (linear interpolation of sin(Delta theta)).
            frac = np.where(crossed, np.abs(self._prev_sin)
                            / np.maximum(np.abs(self._prev_sin - sin_d), 1e-300), -1.0)
            self.last_circle = np.where(crossed.any(axis=1), frac.argmax(axis=1),
                                        self.last_circle)

        goal_in_t = inside_triangle(tgt)                                    # criterion 1
        a_in_t = inside_triangle(cur)
        order_differs = np.any(cyclic_order(cur) != cyclic_order(tgt), axis=-1)  # crit. 2
        # Criterion 3's condition: T not in T^ and A in the other half-plane of the NLP
        # line (theta_NLP - pi changes sign across the line L_i L_j).
        th_a = t.theta[rows, t.nlp]
        th_t = t.theta_goal[rows, t.nlp]
        armed = ~goal_in_t & ((th_a - math.pi) * (th_t - math.pi) < 0)
        prev_in_t = self._prev_in_t if self._prev_in_t is not None else a_in_t
        prev_armed = self._prev_armed if self._prev_armed is not None else armed
        exit_now = prev_in_t & ~a_in_t & prev_armed
        # Criterion 4: on the NLP arc (Delta theta_NLP ~ 0, where the NMV vanishes) for
        # `dwell` steps, away from the goal; trend of the non-NLP differences.
        gain = np.abs(eq1_gain(t.delta))
        is_nlp = np.arange(n_pairs) == t.nlp[:, None]
        d_nlp = t.delta[rows, t.nlp]
        on_arc = np.abs(d_nlp) <= cfg.arc_band
        reached = np.abs(d_nlp) <= cfg.circle_tol
        if self._prev_d_nlp is not None:
            reached |= on_arc & (np.abs(self._prev_d_nlp) <= cfg.arc_band) \
                & (self._prev_d_nlp * d_nlp <= 0)
        self.on_arc_steps = np.where(on_arc & ((self.on_arc_steps > 0) | reached),
                                     self.on_arc_steps + 1, 0)
        if cfg.trend_from == "arrival":
            arrived = (self.on_arc_steps == 1)[:, None]
            self._arrival = np.where(arrived, gain,
                                     gain if self._arrival is None else self._arrival)
        judged = (self.on_arc_steps >= cfg.dwell) & (gain.max(axis=1) > cfg.goal_margin)
        self._gains = (self._gains + [gain])[-(cfg.trend_steps + 1):]
        if cfg.trend_from == "arrival" or len(self._gains) > cfg.trend_steps:
            before = self._arrival if cfg.trend_from == "arrival" else self._gains[0]
            change = np.where(is_nlp, np.nan, gain - before)
            increasing = np.nanmin(change, axis=1) > cfg.trend_margin
            decreasing = np.nanmax(change, axis=1) < -cfg.trend_margin
        else:
            increasing = decreasing = np.zeros(b, dtype=bool)

        status = self.status.copy()
        crit = self.criterion.copy()
        todo = status == UnifiedState.UNCERTAIN

        def decide(mask: np.ndarray, new_status: UnifiedState, which: Criterion) -> None:
            nonlocal todo
            hit = todo & mask
            status[hit] = new_status
            crit[hit] = which
            todo = todo & ~mask

        decide(goal_in_t, UnifiedState.BASIC, Criterion.GOAL_IN_TRIANGLE)
        decide(a_in_t & order_differs, UnifiedState.BASIC, Criterion.GOAL_IN_H)
        decide(exit_now & (self.last_circle == t.nlp), UnifiedState.COMPLEMENTARY,
               Criterion.LAST_CIRCLE_ON_EXIT)
        no_info = (self.last_circle < 0) if cfg.no_crossing == "uncertain" else np.zeros(b, bool)
        decide(exit_now & ~no_info, UnifiedState.BASIC, Criterion.LAST_CIRCLE_ON_EXIT)
        todo = todo & ~armed        # criterion 3 pending: criterion 4 is not consulted
        decide(judged & increasing, UnifiedState.COMPLEMENTARY, Criterion.NLP_CIRCLE_TREND)
        decide(judged & decreasing, UnifiedState.BASIC, Criterion.NLP_CIRCLE_TREND)

        self.status, self.criterion = status, crit
        self._prev_sin, self._prev_in_t, self._prev_armed = sin_d, a_in_t, armed
        self._prev_d_nlp = d_nlp
        signs = _signs(t.nlp, n_pairs, status == UnifiedState.COMPLEMENTARY)
        return (signs[..., None] * t.pair_vectors).sum(axis=-2)


class UnifiedLaw:
    """Unified control law (§2 "The unification of the two local control laws",
    Algorithm 1) for one robot; stateful: make one per run (or call :meth:`reset`).

    Every :meth:`step` first evaluates, while the state is UNCERTAIN, the four geometric
    criteria in Algorithm 1's order, then returns the basic law's vector (UNCERTAIN or
    BASIC) or the complementary law's (COMPLEMENTARY). A decided state never changes.

    1. ``T in T^`` (:func:`inside_triangle` of the goal) -> BASIC.
    2. ``A in T^`` and ``T`` sees another cyclic order of the landmarks than ``A``
       (:func:`cyclic_order`), i.e. ``T in H^`` -> BASIC.
    3. ``T not in T^`` and ``A`` in the half-plane of the NLP line opposite to ``T``
       (``theta_NLP - pi`` and ``theta'_NLP - pi`` of opposite signs). The decision is
       taken when the robot leaves ``T^`` ("the third one only upon exiting this
       triangle"): COMPLEMENTARY if the last landmark-goal circle crossed is the NLP
       circle, else BASIC.
    4. Otherwise, when ``A`` is on the NLP landmark-goal circle: COMPLEMENTARY if the
       non-NLP differences in angular separation are increasing.

    Choices where the paper is silent (``docs/bearing.md`` shows why, with maps):

    * A landmark-goal circle (through ``L_i``, ``L_j``, ``T``) is *crossed* when
      ``sin(Delta theta_ij)`` changes sign between two steps: by the inscribed angle
      theorem the whole circle is ``Delta theta_ij = 0 (mod pi)``. Crossings count from
      the start of the run ("the last landmark-goal circle intersected by the robot before
      leaving T^"); several in one step are ordered by linear interpolation.
    * Criterion 3 decides on the step at which ``A`` leaves ``T^`` if its condition held
      at the previous step (leaving across the NLP edge puts ``A`` on ``T``'s side, so it
      cannot be required at the exit itself). If no circle was crossed at all the state
      stays UNCERTAIN (``no_crossing="uncertain"``): the criterion gave no information,
      and Algorithm 1's ``else -> BASIC`` sends every start inside the NLP disk to the
      wrong law when ``T`` is outside ``C^``. While its condition holds, criterion 4 is
      not consulted (Algorithm 1's ``else if`` chain).
    * Criterion 4, "A is on the NLP landmark-goal circle": the arc where the NMV
      vanishes (``Delta theta_NLP ~ 0``, §2: "close to the arc, the NMV stops
      dominating"), not the opposite arc (``Delta theta_NLP ~ +-pi``, where the NMV is
      largest); "has reached" = reached it and stayed on it for ``dwell`` steps (the
      robot slides along the arc; judging at the first touch misreads the transient).
      "The non-NLP differences ... are increasing": *each* non-NLP ``|g(Delta theta_ij)|``
      grew over the last ``trend_steps`` steps -> COMPLEMENTARY; each shrank -> BASIC (the
      criterion's text: "reachable by the basic control law if ... decreasing");
      mixed -> still UNCERTAIN, judged again at the next step. From noisy bearings
      (pixels), ``trend_from="arrival"`` compares with the values at the arc's arrival
      and counts a change only beyond ``trend_margin``.
    * For ``N > 3`` landmarks the criteria are applied as written with ``T^`` the convex
      hull; the paper's guarantees are for three landmarks.
    """

    def __init__(self, config: UnifiedConfig | None = None) -> None:
        self.config = config or UnifiedConfig()
        self._batch = UnifiedBatch(self.config)

    def reset(self) -> None:
        """Back to UNCERTAIN with no history (a new run)."""
        self._batch = UnifiedBatch(self.config)

    @property
    def state(self) -> UnifiedState:
        """The current state (UNCERTAIN before the first step)."""
        s = self._batch.status
        return UnifiedState.UNCERTAIN if s is None else UnifiedState(int(s[0]))

    @property
    def criterion(self) -> Criterion:
        """The criterion that decided the state (``NONE`` while UNCERTAIN)."""
        c = self._batch.criterion
        return Criterion.NONE if c is None else Criterion(int(c[0]))

    def step(self, current, goal) -> LawResult:
        """One iteration of Algorithm 1: update the state from the snapshots (bearings,
        radians, CCW, of the same ``N >= 3`` landmarks) and return the motion vector."""
        cur, tgt = _single(current, goal)
        self._batch.step(cur[None], tgt[None])
        comp = self.state == UnifiedState.COMPLEMENTARY
        return _result(cur, tgt, complementary=comp, state=self.state,
                       criterion=self.criterion, stop_tol=self.config.stop_tol)


__all__ = ["DEFAULT_STOP_TOL", "LAWS", "Criterion", "LawResult", "UnifiedBatch",
           "UnifiedConfig", "UnifiedLaw", "UnifiedState", "angular_separations",
           "basic_law", "check_bearings", "complementary_law", "cyclic_order", "eq1_gain",
           "inside_triangle", "landmark_pairs", "max_gap", "motion_vectors",
           "nearest_landmark_pair", "snapshots_similar"]
