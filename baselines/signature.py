"""Hong et al. 1991 §2: the one-dimensional location signature and its characteristic points.

The signature is sampled on a bearing grid ``theta_k = (k + 1/2) * 360/n`` degrees
(counter-clockwise from the robot heading, ``k = 0 .. n-1``; ``n = 360``: Hong's 1 degree
interval). On the default panorama width 360 the grid coincides with the column centres
(column ``x`` has bearing ``pi - 2*pi*x/W``, see :mod:`homing_gym.render.panorama`), so the
panorama signature is a reordering of columns without interpolation.

Two sources give the same signature (``tests/homing_baselines/test_snapshot.py`` checks it):

* :func:`signature_from_omni`: §2 equation ``V_i = sum_{j=-2..2} I(i*dtheta, r_h + j*dr)``
  on the env's ``omni`` ring image (the paper's spherical-mirror view), ``r_h`` the
  horizon circle (:func:`homing_gym.render.panorama.omni_horizon_radius`), ``dr`` one pixel;
* :func:`signature_from_panorama`: the same radial average over the panorama rows
  centred on the horizon (the env's ``signature`` observation, reordered by bearing).

We average instead of summing (``V`` in ``[0, 1]`` luminance): the matching of §3 is
normalised, only the reshaping constant ``k_low`` is in these units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from homing_gym.render.panorama import bearing_column, omni_horizon_radius, signature_weights
from homing_gym.vision import luminance


def bearing_grid(n: int) -> np.ndarray:
    """Bearings (radians, CCW from heading) of the ``n`` signature samples."""
    if not (isinstance(n, (int, np.integer)) and n >= 16):
        raise ValueError(f"the signature needs an integer n >= 16 samples, got {n!r}")
    return (np.arange(n) + 0.5) * 2 * np.pi / n


def _luminance(image: np.ndarray) -> np.ndarray:
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"expected an RGB image (H, W, 3), got shape {image.shape}")
    return luminance(image)


def columns_to_bearings(column_signature: np.ndarray, n: int = 360) -> np.ndarray:
    """A per-column signature (panorama order, e.g. the env's ``signature`` observation)
    resampled on the bearing grid of :func:`bearing_grid` (circular linear interpolation;
    a pure reordering when ``n`` equals the panorama width)."""
    sig = np.asarray(column_signature, dtype=np.float32)
    if sig.ndim != 1:
        raise ValueError(f"expected a 1-D per-column signature, got shape {sig.shape}")
    W = sig.shape[0]
    x = bearing_column(bearing_grid(n), W) - 0.5      # in column-centre units
    lo = np.floor(x).astype(int)
    frac = (x - lo).astype(np.float32)
    return (1 - frac) * sig[lo % W] + frac * sig[(lo + 1) % W]


def signature_from_panorama(panorama: np.ndarray, n: int = 360, rows: int = 5) -> np.ndarray:
    """§2 signature from a cylindrical panorama: luminance averaged over ``rows`` samples one
    row apart centred on the horizon, on the ``n``-sample bearing grid. float32 ``(n,)``."""
    gray = _luminance(panorama)
    weights = signature_weights(gray.shape[0], rows)
    return columns_to_bearings(weights @ gray, n)


def signature_from_omni(omni: np.ndarray, n: int = 360, radial: int = 5,
                        dr: float = 1.0) -> np.ndarray:
    """§2 signature from the ``omni`` ring image: at each bearing ``theta_k`` the mean of
    ``radial`` samples ``dr`` pixels apart centred on the horizon circle (bilinear).
    float32 ``(n,)``."""
    if omni.ndim != 3 or omni.shape[0] != omni.shape[1]:
        raise ValueError(f"expected a square ring image (S, S, 3), got shape {omni.shape}")
    if radial < 1 or not dr > 0:
        raise ValueError(f"need radial >= 1 samples and dr > 0 pixels, got {radial}, {dr}")
    S = omni.shape[0]
    theta = bearing_grid(n)[None, :]
    r = omni_horizon_radius(S) + (np.arange(radial) - (radial - 1) / 2)[:, None] * dr
    # ring convention: heading up, bearings CCW; pixel i has its centre at i + 1/2
    map_x = (S / 2 - r * np.sin(theta) - 0.5).astype(np.float32)
    map_y = (S / 2 - r * np.cos(theta) - 0.5).astype(np.float32)
    samples = cv2.remap(_luminance(omni), map_x, map_y, cv2.INTER_LINEAR,
                        borderMode=cv2.BORDER_REPLICATE)
    return samples.mean(axis=0).astype(np.float32)


@dataclass(frozen=True)
class CharacteristicPoints:
    """Characteristic points of a signature (§2), best rank first.

    ``index``: sample ``k`` of the steepest step ``V[k] -> V[k+1]`` of each monotonic
    segment; ``bearing``: its bearing (radians, the step's midpoint ``theta_k + dtheta/2``);
    ``instant``: ``|V[k+1] - V[k]|``; ``total``: total change across the segment;
    ``sparseness``: angular distance (degrees) between its left and right neighbouring
    potential points; ``rank``: ``sparseness * total``.
    """

    index: np.ndarray
    bearing: np.ndarray
    instant: np.ndarray
    total: np.ndarray
    sparseness: np.ndarray
    rank: np.ndarray
    n_potential: int

    def __len__(self) -> int:
        return len(self.index)


def monotonic_segments(signature: np.ndarray) -> list[np.ndarray]:
    """§2 step 1: the circular signature split into runs of monotonic intensity. Each run
    is the array of step indices ``k`` (step ``V[k] -> V[(k+1) % n]``) sharing one sign;
    flat steps join the run they follow."""
    v = np.asarray(signature, dtype=np.float64)
    d = np.roll(v, -1) - v
    sign = np.sign(d)
    if not np.any(sign):
        return []
    # carry the last non-zero sign over flat steps (circularly)
    nz = np.flatnonzero(sign)
    idx = nz[np.searchsorted(nz, np.arange(len(v)), side="right") - 1]  # -1 wraps to last
    sign = sign[idx]
    starts = np.flatnonzero(sign != np.roll(sign, 1))
    if len(starts) == 0:  # monotonic all round is impossible on a circle, but be safe
        return [np.arange(len(v))]
    segments = []
    for a, b in zip(starts, np.roll(starts, -1)):
        length = (b - a) % len(v) or len(v)
        segments.append((a + np.arange(length)) % len(v))
    return segments


def characteristic_points(signature: np.ndarray, n_points: int = 15,
                          min_instant: float = 0.02, min_total: float = 0.08
                          ) -> CharacteristicPoints:
    """§2 characteristic points: (1) segment into monotonic runs; (2) in each, the step of
    maximum instantaneous change, accepted as a potential point if that change is at least
    ``min_instant`` or the segment's total change at least ``min_total`` (luminance units,
    signature in ``[0, 1]``); (3) rank by ``S_i * Delta_i`` (sparseness times total change)
    and keep the top ``n_points`` (Hong: 15)."""
    if not (isinstance(n_points, (int, np.integer)) and n_points >= 1):
        raise ValueError(f"n_points must be an integer >= 1, got {n_points!r}")
    if not (min_instant >= 0 and min_total >= 0):
        raise ValueError(f"acceptance thresholds must be >= 0, got {min_instant}, {min_total}")
    v = np.asarray(signature, dtype=np.float64)
    n = len(v)
    d = np.roll(v, -1) - v
    idx, inst, tot = [], [], []
    for seg in monotonic_segments(v):
        k = seg[np.argmax(np.abs(d[seg]))]
        change, total = abs(d[k]), abs(d[seg].sum())
        if change >= min_instant or total >= min_total:
            idx.append(k)
            inst.append(change)
            tot.append(total)
    idx_a = np.array(idx, dtype=int)
    order = np.argsort(idx_a)
    idx_a, inst_a, tot_a = idx_a[order], np.array(inst)[order], np.array(tot)[order]
    m = len(idx_a)
    if m == 0:
        sparse = np.zeros(0)
    elif m == 1:
        sparse = np.array([float(n)])
    else:
        gaps = (np.roll(idx_a, -1) - idx_a) % n           # to the next point (CCW)
        sparse = (gaps + np.roll(gaps, 1)).astype(np.float64)  # next minus previous
    sparse_deg = sparse * 360.0 / n
    rank = sparse_deg * tot_a
    best = np.argsort(-rank, kind="stable")[:n_points]
    step = 2 * math.pi / n
    return CharacteristicPoints(
        index=idx_a[best], bearing=(idx_a[best] + 1.0) * step, instant=inst_a[best],
        total=tot_a[best], sparseness=sparse_deg[best], rank=rank[best], n_potential=m)
