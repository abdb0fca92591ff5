"""``snapshot``: Hong et al. 1991 image-based homing (§2-§4), from the horizon signature.

Pipeline of :func:`hong_homing` (current view, target view) -> :class:`HomingEstimate`:

1. §2: both views become 360-sample location signatures (:mod:`homing_baselines.signature`); up
   to 15 characteristic points are picked in the *current* signature ``V``.
2. §3: each point's 13-sample window is matched against windows of the target signature
   ``V^T`` with the reshaped, deviation-corrected, L1-normalised difference
   ``rho_ij = k_high/(k_low + mu^T) * sum_l w_l |(V_{i+l} - mu) - sigma/sigma^T (V^T_{j+l} - mu^T)|``
   where ``mu``, ``1/sigma`` are the weighted mean and reciprocal mean absolute deviation of
   the current window and ``mu^T``, ``1/sigma^T`` those of the target window centred on the
   deviation-corrected place ``i + psi`` (§3, last equations).
3. §3: deviation (body rotation) ``psi`` and home direction ``omega`` are searched jointly
   for the smallest ``sum_i rho_{i,j_best}``: ``psi`` in ``psi_est +- k_psi``, ``omega`` in
   ``omega^0 +- k_omega``; point ``i`` may match any ``j`` between
   ``i + psi - k_front sin(theta_i - omega)`` and ``i + psi + k_back sin(theta_i - omega)``.
4. §4: the home direction from the best correspondences with the T->C symmetric estimate
   and the ``|phi - psi| S / rho`` weighting, averaged with the searched direction:
   ``omega_final = (omega + omega_est) / 2``.

Choices where the paper is ambiguous (documented in ``docs/hong.md``):

* Harmonic weights ``w_l = 1/(2 + |l|)`` (the printed ``1/|2 + l|`` is infinite at l = -2).
* Angles: bearings are counter-clockwise (the §4 formulas hold in this orientation, see
  ``docs/hong.md``). ``psi = yaw_current - yaw_target``, so a landmark at bearing ``theta``
  now is at ``theta + psi`` in the target view; ``omega`` is expressed in the *target's*
  frame (the paper's body never rotates; ours turns before every step), the robot-frame
  direction is ``omega_final - psi``. Offsets enter the §4 formulas with the deviation
  removed, ``p_i = phi_i - psi`` (the paper writes ``phi_i - psi`` in the sign and
  ``phi_i / 2`` in the angle; both agree when ``psi ~ 0``, as in its robot where ``psi`` < 3 deg);
  the interval uses the bearing ``theta_i + psi - omega`` relative to home, likewise.
* ``psi_est`` (§3): the weighted mean of the offsets with weights ``S_i sin^2(theta_i) /
  rho_i`` (the printed weight multiplies by ``rho``, a *difference*, which would favour the
  worst matches; §4 divides by it) around a global first alignment ``psi'`` (the best
  deviation with a symmetric +-k_back interval; our robot can face any way, §3 allows
  ``k_psi`` up to 180 deg). ``omega^0`` comes from the §4 weighted formula at ``psi'``.
* Equal-cost ties of the search in ``omega`` are resolved by the circular mean of the tied
  directions (a plateau arises because intervals are whole samples).
* ``sigma`` is floored (``sigma_floor``) so flat windows cannot divide by 0. ``rho`` is
  floored at ``rho_floor`` = 0.01, about a tenth of a typical best match (0.03-0.1), in the
  §4 weight ``|phi - psi| S / rho``: the paper does not say what a near-perfect match
  weighs; with the old floor (1e-3) one such match, typically a distant wall that barely
  changes, outweighed all other points 20-fold and turned the weighted direction by up to
  60 deg (``docs/hong.md``, the 17-target route on the synchro drive).
* A body that keeps its heading (the synchro drive, as the paper's robot: "the body of the
  robot does not rotate", §2) searches deviations within ``k_psi_fixed`` of 0 (default 0:
  the simulated synchro body does not turn at all; the paper's turned by < 3 deg, §3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from homing_baselines.base import Controller
from homing_baselines.motion import Move, integrate
from homing_baselines.signature import (CharacteristicPoints, characteristic_points,
                                 signature_from_omni, signature_from_panorama)
from homing_gym import FOOT
from homing_gym.geometry import wrap_angle
from homing_gym.validation import require_positive

SOURCES = ("panorama", "omni")
TARGET_STATS = ("candidate", "centre")
INITIAL_DEVIATION = ("compass", "search")


@dataclass(frozen=True)
class HongConfig:
    """Constants of Hong et al. 1991 (angles in degrees, intensities in ``[0, 1]``).

    Paper values: ``n_samples`` 360 (1 deg), ``radial`` 5, ``window`` 13, ``n_points`` 15,
    ``k_omega`` 56, ``k_psi`` up to 180, ``k_front`` 0. Changed: ``k_back`` 30 (paper about 8:
    our scenes give larger offsets, see ``docs/hong.md``), ``target_stats`` ``"candidate"``
    (statistics of each candidate target window; ``"centre"``: the literal final §3 form,
    the window at ``i + psi``). Paper-open, our choice (sweep in ``docs/hong.md``):
    ``k_high`` 1 (a common scale of every ``rho``; it cancels in every decision),
    ``k_low`` 0.25, ``min_instant`` 0.02 per sample, ``min_total`` 0.08, ``rho_floor`` 0.01
    (the smallest match value used in the §4 weights). ``omega_step``,
    ``coarse_omega_step``: resolution of the fine and of the first (all-direction) search.
    """

    n_samples: int = 360
    radial: int = 5
    window: int = 13
    n_points: int = 15
    min_instant: float = 0.02
    min_total: float = 0.08
    k_high: float = 1.0
    k_low: float = 0.25
    k_psi: float = 180.0
    k_omega: float = 56.0
    omega_step: float = 1.0
    coarse_omega_step: float = 10.0
    k_front: float = 0.0
    k_back: float = 30.0
    sigma_floor: float = 1e-3
    rho_floor: float = 0.01
    target_stats: str = "candidate"

    def __post_init__(self) -> None:
        checks = [
            ("n_samples", isinstance(self.n_samples, int) and self.n_samples >= 16, ">= 16"),
            ("radial", isinstance(self.radial, int) and self.radial >= 1, ">= 1"),
            ("window", isinstance(self.window, int) and self.window >= 3 and self.window % 2,
             "an odd integer >= 3"),
            ("n_points", isinstance(self.n_points, int) and self.n_points >= 1, ">= 1"),
            ("min_instant", self.min_instant >= 0, ">= 0"),
            ("min_total", self.min_total >= 0, ">= 0"),
            ("k_high", self.k_high > 0, "> 0"),
            ("k_low", self.k_low >= 0, ">= 0"),
            ("k_psi", 0 <= self.k_psi <= 180, "in [0, 180] degrees"),
            ("k_omega", 0 <= self.k_omega <= 180, "in [0, 180] degrees"),
            ("omega_step", 0 < self.omega_step <= 45, "in (0, 45] degrees"),
            ("coarse_omega_step", 0 < self.coarse_omega_step <= 90, "in (0, 90] degrees"),
            ("k_front", 0 <= self.k_front <= 90, "in [0, 90] degrees"),
            ("k_back", 0 <= self.k_back <= 90, "in [0, 90] degrees"),
            ("sigma_floor", self.sigma_floor > 0, "> 0"),
            ("rho_floor", self.rho_floor > 0, "> 0"),
        ]
        bad = [f"{name} must be {rule}, got {getattr(self, name)!r}"
               for name, ok, rule in checks if not ok]
        if self.target_stats not in TARGET_STATS:
            bad.append(f"target_stats must be one of {TARGET_STATS}, got {self.target_stats!r}")
        if self.window >= self.n_samples:
            bad.append(f"window ({self.window}) must be smaller than n_samples ({self.n_samples})")
        if bad:
            raise ValueError("HongConfig: " + "; ".join(bad))

    @property
    def sample_deg(self) -> float:
        """Angular sampling interval ``dtheta`` (degrees)."""
        return 360.0 / self.n_samples


@dataclass
class HomingEstimate:
    """Result of :func:`hong_homing` (radians unless named ``_deg``).

    ``direction``: home direction in the current robot frame (CCW from the heading);
    ``deviation``: ``psi = yaw_current - yaw_target``; ``omega_final``, ``omega_search``
    (``omega_est`` of the search), ``omega_weighted`` (§4 refined formula), ``omega0``,
    ``psi0``: directions and deviations in the target frame; ``cost``: ``sum_i rho_{i,jbest}``;
    ``points``: the characteristic points; ``match``: index in ``V^T`` matched by each;
    ``offset_deg``: ``p_i = phi_i - psi``; ``rho``: best match values. ``valid`` is False
    when the current signature has no characteristic point (then the angles are NaN).
    """

    direction: float
    deviation: float
    omega_final: float
    omega_search: float
    omega_weighted: float
    omega0: float
    psi0: float
    cost: float
    points: CharacteristicPoints
    match: np.ndarray
    offset_deg: np.ndarray
    rho: np.ndarray
    valid: bool = True
    extra: dict[str, Any] = field(default_factory=dict)


def harmonic_weights(window: int) -> np.ndarray:
    """§3 window weights ``w_l = 1/(2 + |l|)``, ``l = -window//2 .. window//2``."""
    half = window // 2
    return 1.0 / (2.0 + np.abs(np.arange(-half, half + 1)))


def _windows(v: np.ndarray, centres: np.ndarray, half: int) -> np.ndarray:
    n = len(v)
    return v[(np.asarray(centres)[..., None] + np.arange(-half, half + 1)) % n]


def _stats(win: np.ndarray, w: np.ndarray, floor: float) -> tuple[np.ndarray, np.ndarray]:
    """§3 weighted mean ``mu`` and L1 deviation ``sigma`` of windows (last axis)."""
    mu = win @ w / w.sum()
    sigma = np.abs(win - mu[..., None]) @ w / w.sum()
    return mu, np.maximum(sigma, floor)


def match_values(v: np.ndarray, vt: np.ndarray, points: np.ndarray, reach: int,
                 config: HongConfig) -> np.ndarray:
    """§3 reshaped, deviation-corrected match values ``rho[p, s, m]`` of characteristic point
    ``points[p]`` (index in ``v``) against ``vt`` at ``j = points[p] + s + m`` for every
    deviation shift ``s`` (samples, ``0 .. n-1``) and offset ``m`` in ``[-reach, reach]``;
    target statistics from the window centred on ``points[p] + s``."""
    n = len(v)
    half = config.window // 2
    w = harmonic_weights(config.window)
    cur = _windows(v, points, half)                                 # (P, L)
    mu, sigma = _stats(cur, w, config.sigma_floor)
    a = cur - mu[:, None]                                           # (P, L)
    tw = _windows(vt, np.arange(n), half)                           # (n, L)
    mu_t, sigma_t = _stats(tw, w, config.sigma_floor)
    centre = (points[:, None] + np.arange(n)[None, :]) % n          # (P, S)
    j = (centre[..., None] + np.arange(-reach, reach + 1)) % n      # (P, S, M)
    at = centre[..., None] if config.target_stats == "centre" else j  # (P, S, 1|M)
    mt = mu_t[at][..., None]
    ratio = (sigma[:, None, None] / sigma_t[at])[..., None]
    diff = np.abs(a[:, None, None, :] - ratio * (tw[j] - mt))       # (P, S, M, L)
    shape = config.k_high / np.maximum(config.k_low + mu_t[at], config.sigma_floor)
    return shape * (diff @ w)


def _direction(theta: np.ndarray, psi: float, offset: np.ndarray, weight: np.ndarray,
               symmetric: bool) -> float | None:
    """§4 homing direction (target frame, radians): ``atan`` of ``sum_i -c_i sin(a_i)`` over
    ``sum_i -c_i cos(a_i)`` with ``a_i = [p_i/2 +] 90deg + theta_i + psi`` and
    ``c_i = weight_i * p_i`` (``weight = 1/|p|``: the plain ``sgn`` form). ``None`` when
    every term vanishes (no offset: no information)."""
    c = weight * offset
    if not np.any(c):
        return None
    ang = theta + psi + np.pi / 2 + (np.radians(offset) / 2 if symmetric else 0.0)
    y, x = np.sum(-c * np.sin(ang)), np.sum(-c * np.cos(ang))
    return math.atan2(y, x) if (x or y) else None


def _circular_mean(*angles: float) -> float:
    return math.atan2(sum(math.sin(a) for a in angles), sum(math.cos(a) for a in angles))


def _interval_min(left: np.ndarray, right: np.ndarray, lo: np.ndarray, hi: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Best value and offset over ``m in [lo, hi]`` (``lo <= 0 <= hi``) from running minima
    towards negative (``left[..., k]``: over ``m in [-k, 0]``) and positive offsets."""
    lv = np.take_along_axis(left[0], -lo, axis=-1)
    rv = np.take_along_axis(right[0], hi, axis=-1)
    use_left = lv < rv
    value = np.where(use_left, lv, rv)
    arg = np.where(use_left, np.take_along_axis(left[1], -lo, axis=-1),
                   np.take_along_axis(right[1], hi, axis=-1))
    return value, arg


def _running(rho: np.ndarray, reach: int) -> tuple[tuple, tuple]:
    """Running minima (value, offset) of ``rho[..., m]`` from ``m = 0`` outwards."""
    def run(seq: np.ndarray, offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        best_val = np.minimum.accumulate(seq, axis=-1)
        # index of the running minimum: first position where it was attained
        is_new = np.concatenate([np.ones(seq.shape[:-1] + (1,), bool),
                                 seq[..., 1:] < best_val[..., :-1]], -1)
        idx = np.maximum.accumulate(np.where(is_new, np.arange(seq.shape[-1]), 0), -1)
        return best_val, offsets[idx]
    m = np.arange(-reach, reach + 1)
    right = run(rho[..., reach:], m[reach:])
    left = run(rho[..., reach::-1], m[reach::-1])
    return left, right


def signature_of(view: np.ndarray, source: str = "panorama", config: HongConfig = HongConfig()
                 ) -> np.ndarray:
    """The §2 signature of a view: a panorama ``(H, W, 3)``, an omni ring image
    ``(S, S, 3)`` (``source="omni"``), or an already computed bearing-ordered signature."""
    view = np.asarray(view)
    if view.ndim == 1:
        if len(view) != config.n_samples:
            raise ValueError(f"a signature must have {config.n_samples} samples, got {len(view)}")
        return view.astype(np.float64)
    if source == "panorama":
        return signature_from_panorama(view, config.n_samples, config.radial).astype(np.float64)
    if source == "omni":
        return signature_from_omni(view, config.n_samples, config.radial).astype(np.float64)
    raise ValueError(f"unknown signature source {source!r}; allowed: {SOURCES}")


def signature_compass(current: np.ndarray, target: np.ndarray) -> float:
    """Deviation ``psi`` (radians) that best aligns two whole signatures (bearing order):
    the circular shift minimising the L1 distance of the mean/L1-normalised signatures
    (the §3 normalisation applied to the whole ring). Not in the paper, whose body never
    rotated; used to centre the deviation search of a first decision."""
    def norm(x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, dtype=np.float64) - np.mean(x)
        return x / max(float(np.mean(np.abs(x))), 1e-6)
    a, b = norm(current), norm(target)
    n = len(a)
    shifted = b[(np.arange(n)[:, None] + np.arange(n)[None, :]) % n]   # [s, k] = b[k + s]
    s = int(np.argmin(np.abs(shifted - a[None, :]).sum(1)))
    return wrap_angle(2 * np.pi * s / n)


def hong_homing(current: np.ndarray, target: np.ndarray, config: HongConfig = HongConfig(),
                source: str = "panorama", psi_prior: float | None = None) -> HomingEstimate:
    """Hong et al. 1991 §2-§4 from a current and a target view (panoramas, omni ring images
    with ``source="omni"``, or signatures): home direction in the current robot frame,
    deviation and diagnostics. Pure: no env needed.

    Deviations are searched within ``config.k_psi`` of ``psi_prior`` (radians, e.g. the
    rotation the robot knows it commanded) or, without a prior, of the §3 estimate
    ``psi_est`` after a first alignment over ``+-k_psi`` about 0; ``k_psi = 180`` searches all.
    """
    v, vt = signature_of(current, source, config), signature_of(target, source, config)
    n, step = config.n_samples, config.sample_deg
    cp = characteristic_points(v, config.n_points, config.min_instant, config.min_total)
    if len(cp) == 0:
        nan = float("nan")
        empty = np.zeros(0)
        return HomingEstimate(nan, nan, nan, nan, nan, nan, nan, nan, cp, empty.astype(int),
                              empty, empty, valid=False)
    theta = cp.bearing
    reach = int(math.ceil(max(config.k_front, config.k_back) / step))
    rho = match_values(v, vt, cp.index, reach, config)            # (P, n, M)
    runs = _running(rho, reach)

    def psi_window(centre_deg: float) -> np.ndarray:
        if config.k_psi >= 180:
            return np.arange(n)
        k = int(round(config.k_psi / step))
        return (int(round(centre_deg / step)) + np.arange(-k, k + 1)) % n

    # 1. coarse joint search, every direction (gives psi' and the matches for omega^0)
    s_range = psi_window(0.0 if psi_prior is None else math.degrees(psi_prior))
    coarse = np.radians(np.arange(-180.0, 180.0, config.coarse_omega_step))
    _, s1, o1, val1, arg1 = _search(runs, theta, s_range, coarse, config)
    m1, r1 = arg1[:, s1, o1], np.maximum(val1[:, s1, o1], config.rho_floor)
    psi1 = float(s_range[s1] * step)
    # §3 psi_est: weighted mean of the offsets phi_i = psi' + m_i
    wts = cp.sparseness * np.sin(theta) ** 2 / r1
    psi_est = psi1 + (float(np.sum(wts * m1) / wts.sum()) * step if wts.sum() > 0 else 0.0)
    # omega^0: the §4 direction from these matches (the coarse direction if they carry none)
    omega0 = _direction(theta, math.radians(psi1), m1 * step, cp.sparseness / r1, True)
    omega0 = float(coarse[o1]) if omega0 is None else omega0

    # 2. joint search psi in psi_est +- k_psi, omega in omega^0 +- k_omega (§3)
    s_range = psi_window(psi_est if psi_prior is None else math.degrees(psi_prior))
    ko = min(config.k_omega, 180.0 - config.omega_step / 2)
    omegas = omega0 + np.radians(np.arange(-ko, ko + 1e-9, config.omega_step))
    cost, si, _, val, arg = _search(runs, theta, s_range, omegas, config)
    best = float(cost[si].min())
    tied = np.flatnonzero(cost[si] <= best + 1e-9 * max(1.0, abs(best)))
    omega_search = _circular_mean(*omegas[tied])
    oi = int(tied[np.argmin(np.abs(wrap_angle(omegas[tied] - omega_search)))])
    s_best = int(s_range[si])
    psi = math.radians(s_best * step)
    m_best, rho_best = arg[:, si, oi], np.maximum(val[:, si, oi], config.rho_floor)

    # 3. §4 homing direction with the three refinements
    offsets = m_best * step
    omega_w = _direction(theta, psi, offsets, cp.sparseness / rho_best, True)
    omega_weighted = omega_search if omega_w is None else omega_w
    omega_final = _circular_mean(omega_weighted, omega_search)
    return HomingEstimate(
        direction=wrap_angle(omega_final - psi), deviation=wrap_angle(psi),
        omega_final=omega_final, omega_search=wrap_angle(omega_search),
        omega_weighted=wrap_angle(omega_weighted), omega0=wrap_angle(omega0),
        psi0=wrap_angle(math.radians(psi_est)), cost=best, points=cp,
        match=(cp.index + s_best + m_best) % n, offset_deg=offsets.astype(float),
        rho=rho_best, extra={"n_potential": cp.n_potential, "tied_omegas": len(tied),
                             "psi_coarse": wrap_angle(math.radians(psi1))})


def _search(runs: tuple, theta: np.ndarray, s_range: np.ndarray, omegas: np.ndarray,
            config: HongConfig) -> tuple[np.ndarray, int, int, np.ndarray, np.ndarray]:
    """§3 search: for every deviation shift in ``s_range`` and direction in ``omegas``
    (target frame, radians), each point's best match in its interval
    ``[-k_front, k_back] * sin(theta_i + psi - omega)``; returns the cost
    ``sum_i rho_{i,jbest}`` (S, O), the argmin (shift and direction positions) and the
    per-point best values and offsets (P, S, O)."""
    step = config.sample_deg
    left, right = runs
    psi = np.radians(s_range * step)
    sv = np.sin(theta[:, None, None] + psi[None, :, None] - omegas[None, None, :])
    ends_a, ends_b = -config.k_front * sv / step, config.k_back * sv / step
    lo = np.rint(np.minimum(ends_a, ends_b)).astype(int)
    hi = np.rint(np.maximum(ends_a, ends_b)).astype(int)
    val, arg = _interval_min((left[0][:, s_range], left[1][:, s_range]),
                             (right[0][:, s_range], right[1][:, s_range]), lo, hi)
    cost = val.sum(0)
    si, oi = np.unravel_index(int(np.argmin(cost)), cost.shape)
    return cost, int(si), int(oi), val, arg


# -- the controller -------------------------------------------------------------------------
@dataclass
class SnapshotController(Controller):
    """Hong et al. 1991 homing as a controller (§4 motion).

    Per target: steps of 0.6, 0.4, then 0.3 ft (``*_step_ft``, converted to metres) in the
    §4 direction; stop (``None``) when the direction (in the target's frame, where
    successive decisions are comparable) changes by more than ``stop_angle`` = 40 deg from
    the previous step's, or after ``max_steps`` steps (a safety limit of ours, not the
    paper's). After a stop it keeps stopping until the goal snapshot changes (a route's
    next target), then restarts the step schedule.

    Deviation: the paper's robot body never rotates (``psi`` < 3 deg); the differential
    robot turns before each step. The first decision for a target searches every deviation (``k_psi`` = 180,
    the paper's largest; ``initial_deviation="compass"``: +-``k_psi_compass`` about the
    whole-signature alignment instead); later ones search ``k_psi_tracked`` about the
    deviation predicted from the previous one plus the rotation the robot itself
    commanded (the ideal unicycle integral of the planned actions: an efference copy, no
    sensor). A body that keeps its heading (``fixed_heading``; ``None``: true on a synchro
    drive, whose body never turns, as the paper's) searches deviations within
    ``k_psi_fixed`` degrees of 0 at every decision. ``stop_after``: steps taken before the
    40 deg test applies (paper: 1). ``source``: signature from the ``panorama``/``goal`` or
    the ``omni``/``goal_omni`` observation. The remaining fields are :class:`HongConfig`'s.
    """

    source: str = "panorama"
    first_step_ft: float = 0.6
    second_step_ft: float = 0.4
    later_step_ft: float = 0.3
    stop_angle: float = 40.0
    stop_after: int = 1
    max_steps: int = 40
    k_psi_tracked: float = 10.0
    initial_deviation: str = "search"
    k_psi_compass: float = 30.0
    fixed_heading: bool | None = None
    k_psi_fixed: float = 0.0
    n_points: int = HongConfig.n_points
    min_instant: float = HongConfig.min_instant
    min_total: float = HongConfig.min_total
    k_high: float = HongConfig.k_high
    k_low: float = HongConfig.k_low
    k_psi: float = HongConfig.k_psi
    k_omega: float = HongConfig.k_omega
    k_front: float = HongConfig.k_front
    k_back: float = HongConfig.k_back
    target_stats: str = HongConfig.target_stats
    rho_floor: float = HongConfig.rho_floor

    def validate(self) -> None:
        if self.source not in SOURCES:
            raise ValueError(f"snapshot: unknown source {self.source!r}; allowed: {SOURCES}")
        if self.initial_deviation not in INITIAL_DEVIATION:
            raise ValueError(f"snapshot: unknown initial_deviation {self.initial_deviation!r}; "
                             f"allowed: {INITIAL_DEVIATION}")
        for key in ("first_step_ft", "second_step_ft", "later_step_ft"):
            value = getattr(self, key)
            require_positive(f"snapshot: {key}", value, "feet")
        if not (0 < self.stop_angle <= 180):
            raise ValueError(f"snapshot: stop_angle must be in (0, 180] degrees, "
                             f"got {self.stop_angle!r}")
        if not (isinstance(self.stop_after, int) and self.stop_after >= 1):
            raise ValueError(f"snapshot: stop_after must be an integer >= 1 (steps taken "
                             f"before the stop test applies), got {self.stop_after!r}")
        if self.fixed_heading not in (None, True, False):
            raise ValueError(f"snapshot: fixed_heading must be None (from the drive), True or "
                             f"False, got {self.fixed_heading!r}")
        if not (isinstance(self.max_steps, int) and self.max_steps >= 1):
            raise ValueError(f"snapshot: max_steps must be an integer >= 1, got {self.max_steps!r}")
        common = dict(n_points=self.n_points, min_instant=self.min_instant,
                      min_total=self.min_total, k_high=self.k_high, k_low=self.k_low,
                      k_omega=self.k_omega, k_front=self.k_front, k_back=self.k_back,
                      target_stats=self.target_stats, rho_floor=self.rho_floor)
        self.config = HongConfig(k_psi=self.k_psi, **common)
        self.tracked_config = HongConfig(k_psi=self.k_psi_tracked, **common)
        self.compass_config = HongConfig(k_psi=self.k_psi_compass, **common)
        self.fixed_config = HongConfig(k_psi=self.k_psi_fixed, **common)

    def on_reset(self) -> None:
        self._steps = 0
        self._previous: float | None = None
        self._psi: float | None = None
        self._stopped = False
        self.last_estimate: HomingEstimate | None = None

    def body_keeps_heading(self) -> bool:
        """Whether the body never turns (``fixed_heading``; by default, on a synchro drive)."""
        if self.fixed_heading is None:
            return self.motion_spec.drive == "synchro"
        return bool(self.fixed_heading)

    def observation_keys(self) -> tuple[str, str]:
        return ("panorama", "goal") if self.source == "panorama" else ("omni", "goal_omni")

    def decide(self, observation: dict[str, np.ndarray]) -> Move | None:
        now_key, goal_key = self.observation_keys()
        if now_key not in observation or goal_key not in observation:
            raise ValueError(f"snapshot (source={self.source!r}) needs the observation keys "
                             f"{now_key!r} and {goal_key!r}; got {sorted(observation)} "
                             f"(pass obs_keys to gym.make)")
        goal = observation[goal_key]
        if self.is_new_goal(goal):              # a new target: restart the schedule
            self._steps, self._previous, self._psi, self._stopped = 0, None, None, False
        if self._stopped:
            return None
        if self.body_keeps_heading():
            est = hong_homing(observation[now_key], goal, self.fixed_config, self.source,
                              psi_prior=0.0)
        elif self._psi is None and self.initial_deviation == "search":
            est = hong_homing(observation[now_key], goal, self.config, self.source)
        elif self._psi is None:
            now = signature_of(observation[now_key], self.source, self.config)
            target = signature_of(goal, self.source, self.config)
            est = hong_homing(now, target, self.compass_config, self.source,
                              psi_prior=signature_compass(now, target))
        else:
            est = hong_homing(observation[now_key], goal, self.tracked_config, self.source,
                              psi_prior=self._psi)
        self.last_estimate = est
        if not est.valid:
            self._stopped = True
            return None
        if self._previous is not None and self._steps >= self.stop_after and (
                abs(math.degrees(wrap_angle(est.omega_final - self._previous))) > self.stop_angle
                or self._steps >= self.max_steps):
            self._stopped = True     # §4: overshoot assumed, the target is reached
            return None
        schedule = (self.first_step_ft, self.second_step_ft, self.later_step_ft)
        move = Move(est.direction, schedule[min(self._steps, 2)] * FOOT)
        self._steps += 1
        self._previous = est.omega_final
        turn = float(integrate(self._helper.plan(move), self._helper.spec)[2])
        self._psi = wrap_angle(est.deviation + turn)
        return move
