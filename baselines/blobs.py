"""Coloured-blob landmarks of a panorama (Bekris, Argyros & Kavraki §4, "Centroids of
colored blobs"): colour segmentation, connected components, centroid -> bearing.

The paper tracks three coloured posters with a Bayesian colour classifier and takes the
bearing of each blob's centroid; landmark identity is the colour. We segment each colour
with an OpenCV HSV box (:class:`BlobColor`), keep the largest 8-connected component of
each colour (at least ``min_area`` pixels) and convert the centroid column ``x`` into a
bearing with the panorama convention of :mod:`homing_gym.render.panorama`:
``beta = pi - 2*pi*x/W`` (radians, counter-clockwise from the heading).

**The seam.** The panorama's left and right edges (``x = 0`` and ``x = W``, straight
behind) are the same direction. Each colour mask is rolled so that one of its empty
columns sits at the seam before the components are labelled, so a blob straddling the
seam is one component, and its centroid (in rolled columns, mapped back modulo ``W``)
is the circular centroid. A colour present in every column has no centroid and is
reported missing.

Choices: the paper's classifier adapts to illumination; a fixed HSV box is enough for
the simulator's lights (``lighting_change`` may need wider boxes). The centroid is the
mean of the pixel centres ``(j + 0.5, i + 0.5)`` of the component, so it is sub-pixel.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from homing_gym.geometry import wrap_angle
from homing_gym.render.panorama import column_bearing


@dataclass(frozen=True)
class BlobColor:
    """An HSV box of one landmark colour, OpenCV units: ``hue`` (0-180, wraps at 180)
    within ``hue_tolerance``, saturation at least ``min_saturation`` and value at least
    ``min_value`` (0-255)."""

    name: str
    hue: int
    hue_tolerance: int = 10
    min_saturation: int = 140
    min_value: int = 60

    def __post_init__(self) -> None:
        if not self.name:
            raise ValueError("BlobColor needs a name (the landmark's identity)")
        if not 0 <= self.hue < 180:
            raise ValueError(f"colour {self.name!r}: hue must be in [0, 180) OpenCV units, "
                             f"got {self.hue!r}")
        if not 0 <= self.hue_tolerance < 90:
            raise ValueError(f"colour {self.name!r}: hue_tolerance must be in [0, 90), "
                             f"got {self.hue_tolerance!r}")
        for field_name in ("min_saturation", "min_value"):
            value = getattr(self, field_name)
            if not 0 <= value <= 255:
                raise ValueError(f"colour {self.name!r}: {field_name} must be in [0, 255], "
                                 f"got {value!r}")


#: The three poster colours of the ``lab`` scene (red, green, blue panels).
LAB_COLORS: tuple[BlobColor, ...] = (BlobColor("red", 0), BlobColor("green", 60),
                                     BlobColor("blue", 115))


@dataclass(frozen=True)
class Blob:
    """One detected landmark: its colour ``name``, centroid column ``x`` in ``[0, W)`` and
    row ``y`` (pixels, continuous), ``bearing`` (radians, CCW from heading, in
    ``(-pi, pi]``), ``area`` (pixels) and ``width``, the angle the blob spans (radians:
    its columns times ``2 pi / W``; a column of radius ``r`` at distance ``d`` spans
    ``2 asin(r / d)``)."""

    name: str
    x: float
    y: float
    bearing: float
    area: int
    width: float


def color_mask(panorama: np.ndarray, color: BlobColor) -> np.ndarray:
    """uint8 ``(H, W)`` mask (255 inside) of the pixels of ``color`` in an RGB panorama."""
    if panorama.ndim != 3 or panorama.shape[2] != 3 or panorama.dtype != np.uint8:
        raise ValueError(f"panorama must be uint8 (H, W, 3) RGB, got {panorama.dtype} "
                         f"{panorama.shape}")
    hsv = cv2.cvtColor(panorama, cv2.COLOR_RGB2HSV)
    hue = hsv[..., 0].astype(np.int16)
    dh = np.abs(hue - color.hue)
    in_hue = np.minimum(dh, 180 - dh) <= color.hue_tolerance
    ok = in_hue & (hsv[..., 1] >= color.min_saturation) & (hsv[..., 2] >= color.min_value)
    return ok.astype(np.uint8) * 255


def largest_blob(mask: np.ndarray, min_area: int = 4) -> tuple[float, float, int, int] | None:
    """Centroid ``(x, y)`` (continuous pixel coordinates, ``x`` in ``[0, W)``), area and
    width (columns) of the largest 8-connected component of a panorama mask, seam-aware
    (see the module docstring); ``None`` if there is none of ``min_area`` pixels or the
    mask fills every column."""
    W = mask.shape[1]
    empty = np.flatnonzero(~mask.any(axis=0))
    if empty.size == 0:
        return None
    shift = int(empty[0])                      # rolled column c is original (c + shift) % W
    rolled = np.roll(mask, -shift, axis=1)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(rolled, connectivity=8)
    if n <= 1:
        return None
    k = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    area = int(stats[k, cv2.CC_STAT_AREA])
    if area < min_area:
        return None
    ys, xs = np.nonzero(labels == k)
    x = (float(xs.mean()) + 0.5 + shift) % W
    return x, float(ys.mean()) + 0.5, area, int(stats[k, cv2.CC_STAT_WIDTH])


def detect_blobs(panorama: np.ndarray, colors: tuple[BlobColor, ...] = LAB_COLORS,
                 min_area: int = 4) -> dict[str, Blob]:
    """The landmark of each colour that is visible (largest blob of at least ``min_area``
    pixels), keyed by colour name; missing colours are absent."""
    if len({c.name for c in colors}) != len(colors):
        raise ValueError(f"colour names must be distinct, got {[c.name for c in colors]}")
    W = panorama.shape[1]
    out = {}
    for color in colors:
        found = largest_blob(color_mask(panorama, color), min_area)
        if found is not None:
            x, y, area, columns = found
            out[color.name] = Blob(color.name, x, y, wrap_angle(column_bearing(x, W)), area,
                                   2 * np.pi * columns / W)
    return out
