"""Red-landmark perception of Yu & Kim (2011) §III: segmentation, 1-D ring, arcs.

The paper's pipeline (§III, Figs. 8-9): pick the pixels "closer to red", unwrap the
omnidirectional image into a panorama, average a 10-pixel-high horizontal slice into a
one-dimensional ring, and describe each landmark as an arc of that ring by its angular
position θ (the arc midpoint, counter-clockwise from the heading, -180° < θ <= 180°) and
its angular width. The env already gives the unwrapped panorama (``panorama``
observation, :mod:`homing_gym.render.panorama` conventions), so we start from it.

Choices (the paper leaves them open):

* **Segmentation** in OpenCV HSV: a pixel is red if its hue is within ``hue_tolerance``
  of 0 (OpenCV hue 0..180 wraps) and its value is at least ``min_value``; its
  membership grows linearly with saturation from ``saturation_low`` to
  ``saturation_high``. For red blended with the arena's grey/white background the
  saturation is nearly linear in the red fraction of the pixel, so the soft membership
  is the landmark's coverage of the pixel: arc edges get sub-pixel precision, which
  Eq. 1 needs (the step parallax δ is only a few columns).
* **Slice height**: 10 px of the paper's unwrapped image, whose height is the 160 px
  mirror radius (§III), i.e. 1/16 of the panorama height: ``round(H/16)`` rows, at
  least one (3 rows = 3.75° for the default 48-row, 60° panorama).
* **Slice position**: centred ``slice_center_deg`` = -3.1° (below the horizon), so with the
  default camera (0.30 m high) the slice lies on a 38.5 cm cylinder from 0.15 m to
  3.4 m (the arena diagonal), whatever the distance; the light walls are above it.
* **Arcs**: maximal runs of ring values above ``edge_threshold`` whose peak reaches
  ``core_threshold``; θ is the membership-weighted circular centroid of the run, the
  width is the summed membership times the column width. Runs crossing the panorama
  seam (column 0 = W, straight behind) are joined.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from homing_gym.geometry import wrap_angle
from homing_gym.render.panorama import column_bearing

#: The paper's slice: 10 px of an unwrapped image 160 px high (mirror radius, §III).
PAPER_SLICE_FRACTION = 10 / 160


@dataclass(frozen=True)
class RedSegmentation:
    """Parameters of red-landmark extraction (OpenCV HSV units: hue 0-180, S and V 0-255).

    ``vfov_deg`` is the vertical field of view of the panorama (the env's default 60°);
    it only converts ``slice_center_deg`` into rows.
    """

    hue_tolerance: int = 10
    saturation_low: float = 30.0
    saturation_high: float = 210.0
    min_value: int = 40
    slice_fraction: float = PAPER_SLICE_FRACTION
    slice_center_deg: float = -3.1
    vfov_deg: float = 60.0
    edge_threshold: float = 0.1
    core_threshold: float = 0.5
    min_width_deg: float = 0.5

    def __post_init__(self) -> None:
        if not 0 <= self.hue_tolerance < 90:
            raise ValueError(f"hue_tolerance must be in [0, 90) OpenCV hue units, "
                             f"got {self.hue_tolerance!r}")
        if not 0 <= self.saturation_low < self.saturation_high <= 255:
            raise ValueError(f"need 0 <= saturation_low < saturation_high <= 255, got "
                             f"{self.saturation_low!r}, {self.saturation_high!r}")
        if not 0 < self.slice_fraction <= 1:
            raise ValueError(f"slice_fraction must be in (0, 1], got {self.slice_fraction!r}")
        if not 0 < self.vfov_deg <= 180:
            raise ValueError(f"vfov_deg must be in (0, 180], got {self.vfov_deg!r}")
        if abs(self.slice_center_deg) >= self.vfov_deg / 2:
            raise ValueError(f"slice_center_deg {self.slice_center_deg!r} lies outside the "
                             f"+-{self.vfov_deg / 2} deg field of view")
        if not 0 < self.edge_threshold <= self.core_threshold <= 1:
            raise ValueError(f"need 0 < edge_threshold <= core_threshold <= 1, got "
                             f"{self.edge_threshold!r}, {self.core_threshold!r}")


@dataclass(frozen=True)
class Arc:
    """One landmark in the 1-D ring: ``bearing`` θ (radians, CCW from heading, in
    (-π, π]), angular ``width`` (radians), and the run's first and last columns."""

    bearing: float
    width: float
    first: int
    last: int


def red_membership(panorama: np.ndarray, config: RedSegmentation = RedSegmentation()
                   ) -> np.ndarray:
    """Soft red membership in [0, 1] of every pixel of an RGB uint8 panorama, float32 (H, W)."""
    if panorama.ndim != 3 or panorama.shape[2] != 3 or panorama.dtype != np.uint8:
        raise ValueError(f"panorama must be uint8 (H, W, 3) RGB, got {panorama.dtype} "
                         f"{panorama.shape}")
    hsv = cv2.cvtColor(panorama, cv2.COLOR_RGB2HSV)
    hue = hsv[..., 0].astype(np.int16)
    red_hue = (hue <= config.hue_tolerance) | (hue >= 180 - config.hue_tolerance)
    bright = hsv[..., 2] >= config.min_value
    sat = (hsv[..., 1].astype(np.float32) - config.saturation_low) / (
        config.saturation_high - config.saturation_low)
    return np.clip(sat, 0.0, 1.0) * (red_hue & bright)


def slice_rows(height: int, config: RedSegmentation = RedSegmentation()) -> slice:
    """Rows of the horizontal slice (§III's 10 px, scaled to the panorama height)."""
    n = max(1, round(config.slice_fraction * height))
    center = height / 2 - config.slice_center_deg / config.vfov_deg * height
    top = int(round(center - n / 2))
    top = min(max(top, 0), height - n)
    return slice(top, top + n)


def landmark_ring(panorama: np.ndarray, config: RedSegmentation = RedSegmentation()
                  ) -> np.ndarray:
    """The paper's 1-D ring (Fig. 9b): red membership averaged over the slice, (W,) in [0, 1]."""
    rows = slice_rows(panorama.shape[0], config)
    return red_membership(panorama[rows], config).mean(axis=0)


def ring_arcs(ring: np.ndarray, config: RedSegmentation = RedSegmentation()) -> list[Arc]:
    """Arcs of a 1-D ring, seam-aware, sorted by bearing counter-clockwise from -π; none
    when no sample or every sample is landmark (red all round, e.g. a world of red brick:
    no landmark can be told from another, so none has a bearing)."""
    ring = np.asarray(ring, dtype=np.float64)
    W = ring.size
    on = ring > config.edge_threshold
    if not on.any() or on.all():
        return []
    start = int(np.argmin(on))  # an off column: runs cannot wrap past it
    order = (start + np.arange(W)) % W
    arcs = []
    k = 0
    while k < W:
        if not on[order[k]]:
            k += 1
            continue
        j = k
        while j < W and on[order[j]]:
            j += 1
        cols = order[k:j]
        values = ring[cols]
        k = j
        width = float(values.sum()) * 2 * np.pi / W
        if values.max() < config.core_threshold or width < math.radians(config.min_width_deg):
            continue
        # circular centroid of the membership (columns unwrapped from the run's start)
        x = cols[0] + np.arange(cols.size) + 0.5
        centroid = float((values * x).sum() / values.sum())
        arcs.append(Arc(bearing=wrap_angle(column_bearing(centroid, W)), width=width,
                        first=int(cols[0]), last=int(cols[-1])))
    return sorted(arcs, key=lambda a: a.bearing)


def detect_landmarks(panorama: np.ndarray, config: RedSegmentation = RedSegmentation()
                     ) -> list[Arc]:
    """Red landmarks of a panorama as arcs (§III): segmentation, ring, arcs."""
    return ring_arcs(landmark_ring(panorama, config), config)
