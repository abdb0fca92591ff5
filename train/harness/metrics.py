"""Per-episode metrics and their summary (pure functions, no simulator).

Definitions (metres, radians unless named otherwise):

* path length ``p``: sum of the distances between consecutive recorded positions;
* ``spl`` = ``s * l / max(l, p)`` (Anderson et al. 2018), ``s`` success (0/1), ``l`` the
  shortest collision-free start-home path length (:func:`homing_gym.paths.shortest_path`);
* ``soft_spl`` = ``max(0, 1 - d_T / l) * l / max(l, p)`` (Datta et al. 2021), ``d_T`` the
  shortest-path distance from the final position to home;
* bootstrap confidence intervals: percentile bootstrap of the mean, seeded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from homing_gym.paths import path_length

__all__ = ["bootstrap_ci", "distance_bins", "path_length", "soft_spl", "spl"]


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
    """Percentile-bootstrap confidence interval of the mean of ``values`` (seeded, so
    reproducible). NaN for no values."""
    x = np.asarray(values, dtype=np.float64)
    if x.size == 0:
        return math.nan, math.nan
    if not 0 < confidence < 1:
        raise ValueError(f"confidence must be in (0, 1), got {confidence}")
    rng = np.random.default_rng(seed)
    means = x[rng.integers(0, x.size, size=(n_boot, x.size))].mean(axis=1)
    alpha = (1 - confidence) / 2
    lo, hi = np.percentile(means, [100 * alpha, 100 * (1 - alpha)])
    return float(lo), float(hi)


@dataclass(frozen=True)
class DistanceBin:
    """Episodes whose start distance lies in ``[lo, hi)`` metres."""

    lo: float
    hi: float
    n: int
    success_rate: float
    success_ci: tuple[float, float]


def distance_bins(start_distances, successes, width: float = 0.3,
                  seed: int = 0) -> list[DistanceBin]:
    """Success rate by start-distance bin ``[k*width, (k+1)*width)``; only non-empty bins."""
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
                                success_ci=bootstrap_ci(member, seed=seed)))
    return bins
