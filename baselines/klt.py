"""Image-corner features of a panorama (Bekris, Argyros & Kavraki §4, "Image corners"):
Shi-Tomasi corners tracked from frame to frame by pyramidal Lucas-Kanade (the KLT
tracker), on the cylindrical panorama, across its 0/360 degree seam.

:class:`CornerTracker` keeps a set of *tracks*, each with a persistent integer id: a
track found in frame ``t`` keeps its id in every later frame in which it is tracked, so
correspondences between frames are the ids. Each :meth:`CornerTracker.update`

1. tracks every live track from the previous frame into the new one (pyramidal LK,
   ``cv2.calcOpticalFlowPyrLK``) and drops it when LK fails, the forward-backward error
   exceeds ``fb_threshold`` pixels, it leaves the image rows, or it has drifted onto an
   older track (the paper: features that are no longer visible are "dropped");
2. detects new Shi-Tomasi corners (``cv2.goodFeaturesToTrack``) at least
   ``min_distance`` pixels from the live tracks until ``max_features`` are live, and gives
   each a new id.

**The seam.** Both steps run on the panorama padded with ``margin`` columns copied from
the opposite edge, so a corner straddling the seam is detected once and a track crossing
it continues; columns are mapped back modulo ``W``. Bearings follow the panorama
convention of :mod:`homing_gym.render.panorama`, ``beta = pi - 2*pi*x/W`` (radians, CCW).

Paper values (§5, long-range experiment): 100 strongest features, 7 x 7 windows,
Gaussian smoothing with sigma 1.4 on 1394-pixel-wide panoramas. Our panoramas are 5 times
narrower, so the default smoothing is sigma 0.7 (the same blur in degrees is 0.28); the
7 x 7 window is used for the corner measure and a 9 x 9 window for LK (at 256 columns a
7 x 7 LK window holds too little texture).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from homing_gym.geometry import wrap_angle
from homing_gym.render.panorama import column_bearing


@dataclass(frozen=True)
class KLTConfig:
    """Settings of corner detection and tracking (pixels unless said otherwise).

    ``max_features``: live tracks kept (the paper's 100 strongest). ``quality``: Shi-Tomasi
    quality level (fraction of the best corner's score). ``min_distance``: between corners.
    ``block_size``: corner-measure window. ``smoothing_sigma``: Gaussian blur before
    everything (0: none). ``win_size``, ``max_level``: LK window and pyramid levels.
    ``fb_threshold``: largest forward-backward error kept. ``min_eigen``: LK drops a
    track whose window's smaller gradient eigenvalue (per pixel, OpenCV's
    ``minEigThreshold``) falls below this: points sliding along an edge. ``margin``: seam
    padding; must exceed the largest motion between frames plus the LK window.
    """

    max_features: int = 100
    quality: float = 0.01
    min_distance: float = 3.0
    block_size: int = 7
    smoothing_sigma: float = 0.7
    win_size: int = 9
    max_level: int = 2
    fb_threshold: float = 0.5
    min_eigen: float = 1e-3
    margin: int = 24

    def __post_init__(self) -> None:
        if not (isinstance(self.max_features, (int, np.integer)) and self.max_features >= 1):
            raise ValueError(f"max_features must be an integer >= 1, got {self.max_features!r}")
        if not 0 < self.quality < 1:
            raise ValueError(f"quality must be in (0, 1), got {self.quality!r}")
        for name in ("min_distance", "fb_threshold", "min_eigen"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be > 0 pixels, got {getattr(self, name)!r}")
        if self.smoothing_sigma < 0:
            raise ValueError(f"smoothing_sigma must be >= 0, got {self.smoothing_sigma!r}")
        for name in ("block_size", "win_size"):
            value = getattr(self, name)
            if not (isinstance(value, (int, np.integer)) and value >= 3 and value % 2 == 1):
                raise ValueError(f"{name} must be an odd integer >= 3, got {value!r}")
        if not (isinstance(self.max_level, (int, np.integer)) and 0 <= self.max_level <= 5):
            raise ValueError(f"max_level must be an integer in [0, 5], got {self.max_level!r}")
        if not (isinstance(self.margin, (int, np.integer)) and self.margin > self.win_size):
            raise ValueError(f"margin must be an integer > win_size ({self.win_size}), "
                             f"got {self.margin!r}")


def prepare(panorama: np.ndarray, config: KLTConfig) -> np.ndarray:
    """Grey, smoothed panorama padded with ``margin`` wrapped columns on both sides
    (uint8 ``(H, W + 2 margin)``): padded column ``c`` is panorama column ``c - margin``
    modulo ``W``."""
    if panorama.ndim != 3 or panorama.shape[2] != 3 or panorama.dtype != np.uint8:
        raise ValueError(f"panorama must be uint8 (H, W, 3) RGB, got {panorama.dtype} "
                         f"{panorama.shape}")
    W = panorama.shape[1]
    if config.margin >= W:
        raise ValueError(f"KLTConfig.margin {config.margin} must be below the panorama "
                         f"width {W}")
    grey = cv2.cvtColor(panorama, cv2.COLOR_RGB2GRAY)
    m = config.margin
    padded = np.ascontiguousarray(np.hstack([grey[:, -m:], grey, grey[:, :m]]))
    if config.smoothing_sigma > 0:
        padded = cv2.GaussianBlur(padded, (0, 0), config.smoothing_sigma)
    return padded


def track_points(prev: np.ndarray, cur: np.ndarray, points: np.ndarray, config: KLTConfig,
                 guess: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Pyramidal LK of ``points`` ``(n, 2)`` (panorama coordinates ``(x, y)``) from the
    prepared image ``prev`` into ``cur`` (both from :func:`prepare`), optionally starting
    from ``guess`` ``(n, 2)``. Returns the new points (``x`` in ``[0, W)``) and a boolean
    mask of the tracks kept (LK status, forward-backward check, inside the rows)."""
    n = len(points)
    if n == 0:
        return np.zeros((0, 2)), np.zeros(0, dtype=bool)
    m = config.margin
    W = prev.shape[1] - 2 * m
    p0 = np.asarray(points, np.float32).reshape(-1, 1, 2).copy()
    p0[..., 0] = np.mod(p0[..., 0], W) + m
    lk = dict(winSize=(config.win_size, config.win_size), maxLevel=config.max_level,
              criteria=(cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 30, 0.01),
              minEigThreshold=config.min_eigen)
    if guess is not None:
        g = np.asarray(guess, np.float32).reshape(-1, 1, 2).copy()
        # the guess in the padded copy nearest to the start point
        g[..., 0] = p0[..., 0] + wrap_columns(g[..., 0] - (p0[..., 0] - m), W)
        p1, st1, _ = cv2.calcOpticalFlowPyrLK(prev, cur, p0, g,
                                              flags=cv2.OPTFLOW_USE_INITIAL_FLOW, **lk)
    else:
        p1, st1, _ = cv2.calcOpticalFlowPyrLK(prev, cur, p0, None, **lk)
    if guess is not None:   # a predicted large jump: check backwards from its start
        back, st2, _ = cv2.calcOpticalFlowPyrLK(cur, prev, p1, p0.copy(),
                                                flags=cv2.OPTFLOW_USE_INITIAL_FLOW, **lk)
    else:
        back, st2, _ = cv2.calcOpticalFlowPyrLK(cur, prev, p1, None, **lk)
    fb = np.linalg.norm((back - p0).reshape(-1, 2), axis=1)
    p1 = p1.reshape(-1, 2).astype(np.float64)
    H = prev.shape[0]
    ok = (st1.ravel() == 1) & (st2.ravel() == 1) & (fb <= config.fb_threshold) \
        & (p1[:, 1] >= 0) & (p1[:, 1] < H) & (p1[:, 0] >= 0) & (p1[:, 0] < W + 2 * m)
    p1[:, 0] = np.mod(p1[:, 0] - m, W)
    return p1, ok


def wrap_columns(dx, width: int):
    """A column difference wrapped into ``[-W/2, W/2)`` (the shorter way round)."""
    return np.mod(np.asarray(dx, dtype=np.float64) + width / 2, width) - width / 2


def detect_corners(prepared: np.ndarray, config: KLTConfig, count: int,
                   avoid: np.ndarray | None = None) -> np.ndarray:
    """Up to ``count`` Shi-Tomasi corners ``(n, 2)`` of a prepared panorama (``x`` in
    ``[0, W)``), strongest first, each at least ``min_distance`` from the others and
    from the points ``avoid`` ``(k, 2)``."""
    if count <= 0:
        return np.zeros((0, 2))
    m = config.margin
    W = prepared.shape[1] - 2 * m
    mask = np.zeros(prepared.shape, np.uint8)
    mask[:, m:m + W] = 255
    if avoid is not None and len(avoid):
        r = int(np.ceil(config.min_distance))
        for x, y in np.asarray(avoid):
            for copy in (x + m - W, x + m, x + m + W):
                cv2.circle(mask, (int(round(copy)), int(round(y))), r, 0, -1)
    # the corner measure near the seam sees the wrapped padding; the mask keeps each
    # corner once, in the unpadded columns
    corners = cv2.goodFeaturesToTrack(prepared, maxCorners=count, qualityLevel=config.quality,
                                      minDistance=config.min_distance, mask=mask,
                                      blockSize=config.block_size)
    if corners is None:
        return np.zeros((0, 2))
    pts = corners.reshape(-1, 2).astype(np.float64)
    pts[:, 0] -= m
    return pts


def merged(ids: np.ndarray, points: np.ndarray, width: int, radius: float) -> np.ndarray:
    """Tracks that have drifted within ``radius`` pixels of an older track (smaller id):
    LK pulls tracks that lost their texture onto a nearby strong corner, where they
    would be duplicates with wrong identities. Boolean ``(n,)``."""
    dx = wrap_columns(points[:, None, 0] - points[None, :, 0], width)
    dy = points[:, None, 1] - points[None, :, 1]
    close = np.hypot(dx, dy) < radius
    older = ids[None, :] < ids[:, None]
    return (close & older).any(axis=1)


class CornerTracker:
    """KLT tracking with persistent track ids (see the module docstring)."""

    def __init__(self, config: KLTConfig | None = None) -> None:
        self.config = config or KLTConfig()
        self.reset()

    def reset(self) -> None:
        """Forget every track and the previous frame; ids start again at 0."""
        self.ids = np.zeros(0, dtype=np.int64)
        self.points = np.zeros((0, 2))
        self.width = 0
        self._prev: np.ndarray | None = None
        self._next_id = 0

    @property
    def image(self) -> np.ndarray | None:
        """The last frame, prepared (see :func:`prepare`)."""
        return self._prev

    def bearings(self) -> np.ndarray:
        """Bearings (radians, CCW from the heading, in ``(-pi, pi]``) of the live tracks."""
        return wrap_angle(column_bearing(self.points[:, 0], self.width)) if len(self.ids) \
            else np.zeros(0)

    def update(self, panorama: np.ndarray) -> None:
        """Track the live tracks into ``panorama``, drop the lost ones, add new corners."""
        cur = prepare(panorama, self.config)
        self.width = panorama.shape[1]
        if self._prev is not None and self._prev.shape != cur.shape:
            raise ValueError(f"panorama shape changed from {self._prev.shape} to {cur.shape}")
        if self._prev is not None and len(self.ids):
            pts, ok = track_points(self._prev, cur, self.points, self.config)
            self.ids, self.points = self.ids[ok], pts[ok]
            keep = ~merged(self.ids, self.points, self.width, self.config.min_distance / 2)
            self.ids, self.points = self.ids[keep], self.points[keep]
        new = detect_corners(cur, self.config, self.config.max_features - len(self.ids),
                             self.points)
        self.ids = np.concatenate([self.ids, self._next_id + np.arange(len(new))])
        self.points = np.vstack([self.points, new])
        self._next_id += len(new)
        self._prev = cur

    def register(self, reference: np.ndarray, points: np.ndarray, ids: np.ndarray,
                 guess: np.ndarray) -> int:
        """Re-attach features of an earlier frame to the current one (§3: "feature
        selection is then applied to small windows centred at the predicted locations"):
        LK from the prepared ``reference`` frame at ``points`` into the current frame,
        starting at the predicted ``guess``. Tracked ones join the live tracks under their
        old ``ids`` (replacing live tracks with the same id). Returns how many joined."""
        if self._prev is None:
            raise RuntimeError("call update() with a frame before register()")
        pts, ok = track_points(reference, self._prev, points, self.config, guess)
        ids = np.asarray(ids, dtype=np.int64)[ok]
        keep = ~np.isin(self.ids, ids)
        self.ids = np.concatenate([self.ids[keep], ids])
        self.points = np.vstack([self.points[keep], pts[ok]])
        return int(ok.sum())
