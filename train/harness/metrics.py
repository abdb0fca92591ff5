"""Per-episode metrics and their summary (pure functions, no simulator).

Definitions (metres, radians unless named otherwise):

* path length ``p``: sum of the distances between consecutive recorded positions;
* ``spl`` = ``s * l / max(l, p)`` (Anderson et al. 2018), ``s`` success (0/1), ``l`` the
  shortest collision-free start-home path length for a disc of the task's
  ``path_radius`` (:func:`homing_gym.paths.shortest_path`, the path the oracle plans;
  on a route, through every target in order); every episode the env draws has one, and
  the harness refuses one without (a start or home given out of reach);
* ``soft_spl`` = ``max(0, 1 - d_T / l) * l / max(l, p)`` (Datta et al. 2021), ``d_T`` the
  shortest-path distance from the final position to home (infinite, soft-SPL 0, where
  no path leads home from there);
* on a route (RouteFollowing-v0; the env's ``info["target_errors"]`` holds the distance
  at which each target was left: on reaching it, or with ``success_on="stop"`` where the
  agent stopped), a target is *reached* when a recorded position comes within the
  success radius of it, each target at a later position than the one before
  (:func:`targets_reached_in_order`); the episode is *reached* when every target was,
  in order, and *all targets within radius* when it left every target within the radius;
* a failed episode's kind (:func:`failure_kind`): *stuck* (out of time, in contact with
  something in at least 30 % of its steps), *out of time* (elsewhere), *stopped near*
  (within 0.1 m beyond the success radius), *stopped away*;
* confidence intervals from ``scipy.stats``: a success rate's is the Wilson score interval
  (:func:`wilson_interval`, ``binomtest(...).proportion_ci``), a continuous metric's the
  percentile bootstrap of its mean (:func:`bootstrap_ci`, ``scipy.stats.bootstrap``, seeded);
* aggregate success over several strata (scenes, protocols): the mean and the interquartile
  mean (IQM) of the per-stratum success rates, with percentile intervals of the *stratified*
  bootstrap (:func:`aggregate_success`: episodes resampled within each stratum, as rliable's
  ``StratifiedBootstrap``; Agarwal et al. 2021, "Deep reinforcement learning at the edge of
  the statistical precipice").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable

import numpy as np
from scipy import stats

from homing_gym.paths import path_length

__all__ = ["Aggregate", "FAILURE_KINDS", "aggregate_success", "bootstrap_ci", "distance_bins",
           "failure_kind", "path_length", "soft_spl", "spl", "targets_reached_in_order",
           "wilson_interval"]


def spl(success: bool, shortest: float, path: float) -> float:
    """Success weighted by path length: ``s * l / max(l, p)``; 0 when ``l`` is 0."""
    if shortest < 0 or path < 0:
        raise ValueError(f"lengths must be >= 0, got shortest={shortest}, path={path}")
    if shortest == 0:
        return float(bool(success))
    return float(bool(success)) * shortest / max(shortest, path)


def soft_spl(final_distance: float, shortest: float, path: float) -> float:
    """``max(0, 1 - d_T / l) * l / max(l, p)``: progress towards home weighted by
    path efficiency, without the success threshold."""
    if shortest <= 0:
        return 1.0 if final_distance <= 0 else 0.0
    return max(0.0, 1.0 - final_distance / shortest) * shortest / max(shortest, path)


def targets_reached_in_order(positions, targets, radius: float) -> int:
    """How many of the route's ``targets`` (K x 2, metres, in order) the recorded
    ``positions`` (T x 2) reached in order: target 0 at the first position closer than
    ``radius`` to it, target 1 at a later position, and so on (as the env moves its goal
    on after a step), up to the first target not reached."""
    xy = np.asarray(positions, dtype=np.float64).reshape(-1, 2)
    t = 0
    for k, target in enumerate(np.asarray(targets, dtype=np.float64).reshape(-1, 2)):
        within = np.flatnonzero(np.hypot(*(xy[t:] - target).T) < radius)
        if within.size == 0:
            return k
        t += int(within[0]) + 1
    return len(targets)


def bootstrap_ci(values, confidence: float = 0.95, n_boot: int = 2000,
                 seed: int = 0) -> tuple[float, float]:
    """Percentile-bootstrap confidence interval of the mean of ``values``
    (``scipy.stats.bootstrap``, seeded, so reproducible). NaN for no values; the value
    itself for one value or identical values."""
    x = np.asarray(values, dtype=np.float64)
    _check_confidence(confidence)
    if x.size == 0:
        return math.nan, math.nan
    if np.all(x == x[0]):
        return float(x[0]), float(x[0])
    return _percentile_bootstrap((x,), np.mean, confidence, n_boot, seed)


def _percentile_bootstrap(samples, statistic, confidence: float, n_boot: int,
                          seed: int) -> tuple[float, float]:
    """Percentile interval of ``statistic(*samples, axis=-1)`` (vectorised) under the
    bootstrap that resamples each sample on its own (``scipy.stats.bootstrap``, unpaired,
    seeded)."""
    ci = stats.bootstrap(tuple(samples), statistic, confidence_level=confidence,
                         n_resamples=n_boot, method="percentile", paired=False,
                         random_state=np.random.default_rng(seed),
                         vectorized=True).confidence_interval
    return float(ci.low), float(ci.high)


@dataclass(frozen=True)
class Aggregate:
    """Success aggregated over strata: the mean and the IQM (25% trimmed mean) of the
    per-stratum success rates (fractions), each with its stratified-bootstrap interval."""

    strata: int
    episodes: int
    mean: float
    mean_ci: tuple[float, float]
    iqm: float
    iqm_ci: tuple[float, float]


def _mean_rate(*strata, axis: int = -1):
    return np.mean(np.stack([s.mean(axis=axis) for s in strata], axis=-1), axis=-1)


def _iqm_rate(*strata, axis: int = -1):
    return stats.trim_mean(np.stack([s.mean(axis=axis) for s in strata], axis=-1), 0.25,
                           axis=-1)


def aggregate_success(counts: Iterable[tuple[int, int]], confidence: float = 0.95,
                      n_boot: int = 10_000, seed: int = 0) -> Aggregate:
    """Mean and IQM over strata of the success rate, from ``counts``: one
    ``(successes, episodes)`` pair per stratum (e.g. per scene of a protocol).

    Every stratum counts once whatever its episodes (rliable's convention: tasks weigh
    alike); the IQM is ``scipy.stats.trim_mean(rates, 0.25)``, which with fewer than 4
    strata trims nothing and equals the mean. Intervals: percentile, stratified bootstrap
    (episodes resampled with replacement within each stratum, strata kept), seeded. Episodes
    are Bernoulli trials, so a stratum's ``k`` of ``n`` is all the bootstrap needs: it
    resamples ``k`` ones and ``n - k`` zeros, whose order does not matter. A stratum at 0%
    or 100% (one episode included) stays there in every resample and enters as a constant;
    where all are, the interval has zero width, and the per-stratum Wilson intervals are
    the honest bound."""
    counts = [(int(k), int(n)) for k, n in counts]
    if not counts:
        raise ValueError("aggregate_success needs at least one stratum")
    for k, n in counts:
        if n < 1 or not 0 <= k <= n:
            raise ValueError(f"each stratum needs 0 <= successes <= episodes >= 1, got {k}/{n}")
    _check_confidence(confidence)
    rates = np.array([k / n for k, n in counts])
    mean, iqm = float(rates.mean()), float(stats.trim_mean(rates, 0.25))
    varying = [np.repeat([1.0, 0.0], [k, n - k]) for k, n in counts if 0 < k < n]
    if not varying:                        # no stratum can vary under resampling
        return Aggregate(len(counts), sum(n for _, n in counts), mean, (mean, mean), iqm,
                         (iqm, iqm))
    fixed = [np.full(1, k / n) for k, n in counts if k in (0, n)]

    def with_fixed(statistic):
        def of(*strata, axis: int = -1):
            shape = strata[0].shape[:-1] + (1,)
            return statistic(*strata, *(np.broadcast_to(f, shape) for f in fixed), axis=axis)
        return of

    return Aggregate(len(counts), sum(n for _, n in counts), mean,
                     _percentile_bootstrap(varying, with_fixed(_mean_rate), confidence,
                                           n_boot, seed),
                     iqm, _percentile_bootstrap(varying, with_fixed(_iqm_rate), confidence,
                                                n_boot, seed))


def wilson_interval(successes: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of the success rate ``successes / n``
    (``scipy.stats.binomtest(...).proportion_ci``). NaN for ``n == 0``."""
    _check_confidence(confidence)
    if n == 0:
        return math.nan, math.nan
    if not 0 <= successes <= n:
        raise ValueError(f"successes must lie in [0, n={n}], got {successes}")
    ci = stats.binomtest(int(successes), int(n)).proportion_ci(confidence_level=confidence,
                                                               method="wilson")
    return float(ci.low), float(ci.high)


def _check_confidence(confidence: float) -> None:
    if not 0 < confidence < 1:
        raise ValueError(f"confidence must be in (0, 1), got {confidence}")


@dataclass(frozen=True)
class DistanceBin:
    """Episodes whose start distance lies in ``[lo, hi)`` metres."""

    lo: float
    hi: float
    n: int
    success_rate: float
    success_ci: tuple[float, float]


def distance_bins(start_distances, successes, width: float = 0.3) -> list[DistanceBin]:
    """Success rate with its Wilson interval by start-distance bin
    ``[k*width, (k+1)*width)``; only non-empty bins."""
    if not width > 0:
        raise ValueError(f"bin width must be positive metres, got {width}")
    d = np.asarray(start_distances, dtype=np.float64)
    s = np.asarray(successes, dtype=np.float64)
    if d.shape != s.shape:
        raise ValueError("start_distances and successes must have the same length")
    index = np.floor(d / width + 1e-9).astype(int)
    bins = []
    for k in sorted(set(index.tolist())):
        member = s[index == k]
        bins.append(DistanceBin(lo=round(k * width, 6), hi=round((k + 1) * width, 6),
                                n=int(member.size), success_rate=float(member.mean()),
                                success_ci=wilson_interval(int(member.sum()), member.size)))
    return bins


#: How a failed episode ended (:func:`failure_kind`), in the order tables list them.
FAILURE_KINDS = ("stuck", "out of time", "stopped near", "stopped away")
#: An episode out of time with contact in at least this fraction of its steps was stuck.
STUCK_CONTACT = 0.3
#: A stop at most this far (metres) beyond the success radius was near.
NEAR_MARGIN = 0.1


def failure_kind(truncated: bool, steps: int, collisions: int, final_distance: float,
                 radius: float) -> str:
    """What a failed episode did: out of time with contact (robot against a wall or
    object) in at least :data:`STUCK_CONTACT` of its ``steps``, ``"stuck"``; out of time
    otherwise, ``"out of time"``; ended (stopped) within ``radius`` +
    :data:`NEAR_MARGIN` metres of home, ``"stopped near"``; farther, ``"stopped away"``."""
    if truncated:
        return "stuck" if collisions >= STUCK_CONTACT * max(steps, 1) else "out of time"
    return "stopped near" if final_distance <= radius + NEAR_MARGIN else "stopped away"
