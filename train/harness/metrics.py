"""Per-episode metrics and their summary (pure functions, no simulator).

Definitions (metres, radians unless named otherwise):

* path length ``p``: sum of the distances between consecutive recorded positions;
* ``spl`` = ``s * l / max(l, p)`` (Anderson et al. 2018), ``s`` success (0/1), ``l`` the
  shortest collision-free start-home path length (:func:`homing_gym.paths.shortest_path`;
  on a route, through every target in order);
* ``soft_spl`` = ``max(0, 1 - d_T / l) * l / max(l, p)`` (Datta et al. 2021), ``d_T`` the
  shortest-path distance from the final position to home;
* confidence intervals from ``scipy.stats``: a success rate's is the Wilson score interval
  (:func:`wilson_interval`, ``binomtest(...).proportion_ci``), a continuous metric's the
  percentile bootstrap of its mean (:func:`bootstrap_ci`, ``scipy.stats.bootstrap``, seeded).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from homing_gym.paths import path_length

__all__ = ["bootstrap_ci", "distance_bins", "path_length", "soft_spl", "spl", "wilson_interval"]


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
    ci = stats.bootstrap((x,), np.mean, confidence_level=confidence, n_resamples=n_boot,
                         method="percentile", random_state=np.random.default_rng(seed),
                         vectorized=True).confidence_interval
    return float(ci.low), float(ci.high)


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
