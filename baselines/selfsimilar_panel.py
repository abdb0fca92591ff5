"""Where a detected landmark panel stands: its centre and normal in the robot frame, from
one image (for the servoing of Briggs, Scharstein et al. 2000 §4: "in front of A at a
fixed distance").

The paper gets a landmark's distance "from its size in an image" and its angle "from its
horizontal location" (§4.1); to stand *in front of* a panel the robot also needs the
panel's orientation, which the paper does not discuss. We measure the apparent height,
hence the distance (:meth:`CameraModel.distance`), at two columns of the panel whose
positions along it are known from the layout:

* the middle of the dark stripe ``(p^1.5, p]`` of the pattern (pattern coordinate
  ``u1 = (p^1.5 + p) / 2``; dark from top to bottom of the pattern), located on the
  detection's middle row as the second dark stripe from the pattern's right end;
* the middle of the barcode column (``u2 = layout.barcode_centre``; its guard bands
  span the pattern's height).

Each column's extent is the first and last row darker than halfway between the
detection's dark and bright levels, within a quarter of the pattern's height around
the detected extent, located to a fraction of a pixel by linear interpolation. The two
points, each at its bearing and distance, give the panel's direction; the normal is
perpendicular to it, towards the camera. At 2 m straight on, the heights are about 60
pixels in a 320 x 240 view with 60 degrees of field of view; a 0.3 pixel error in an
edge turns the normal by about 5 degrees (more far away, less close by).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from homing_baselines.camera_models import CameraModel
from homing_baselines.selfsimilar_detector import Detection
from homing_gym.selfsimilar import PanelLayout

#: Accepted ratio of the measured to the known distance between the two columns.
SCALE_RANGE = (0.5, 2.0)


@dataclass(frozen=True)
class PanelPose:
    """A panel seen from the robot: ``centre`` (x, y) of its face (metres, robot frame,
    x ahead, y left) and ``normal`` (radians, robot frame), the direction out of the
    panel's face into the room."""

    centre: tuple[float, float]
    normal: float


def _column(gray: np.ndarray, x: float) -> np.ndarray:
    """Column coordinate ``x`` of ``gray`` (linear interpolation between columns)."""
    i = int(math.floor(x))
    f = x - i
    return gray[:, i] * (1 - f) + gray[:, i + 1] * f


def dark_extent(gray: np.ndarray, x: float, top: float, bottom: float,
                threshold: float) -> tuple[float, float] | None:
    """Rows (fractional) of the upper and lower edges of the dark part of column ``x``
    between ``top`` and ``bottom`` widened by a quarter of their distance, or ``None``
    when the column leaves the image or nothing is dark."""
    if not 0 <= x < gray.shape[1] - 1:
        return None
    margin = 0.25 * (bottom - top)
    y0 = max(0, int(math.floor(top - margin)))
    y1 = min(gray.shape[0], int(math.ceil(bottom + margin)) + 1)
    column = _column(gray, x)[y0:y1]
    dark = np.flatnonzero(column < threshold)
    if dark.size == 0 or dark[0] == 0 or dark[-1] == column.size - 1:
        return None                 # not dark, or the dark part touches the window

    def crossing(i_bright: int, i_dark: int) -> float:
        a, b = column[i_bright], column[i_dark]
        return i_bright + (i_dark - i_bright) * (a - threshold) / (a - b)

    return y0 + crossing(dark[0] - 1, dark[0]), y0 + crossing(dark[-1] + 1, dark[-1])


def _second_dark_stripe(profile: np.ndarray, threshold: float) -> float | None:
    """Middle (pixels from the origin) of the second dark stripe from the right end of
    the pattern ``profile`` (sample ``t`` at ``t`` pixels from the origin, ending at
    sigma): the stripe ``(p^1.5, p]``, found from the intensities rather than from
    ``u * sigma``, which perspective shifts by several pixels close by."""
    dark = profile < threshold
    i = dark.size - 1
    for want in (True, False):               # the last dark stripe, then the bright one
        while i > 0 and not dark[i] and want:
            i -= 1
        while i > 0 and dark[i] == want:
            i -= 1
    end = i
    while i > 0 and dark[i]:
        i -= 1
    return 0.5 * (i + 1 + end) if end > i and i > 0 else None


def panel_pose(gray: np.ndarray, det: Detection, model: CameraModel, p: float,
               layout: PanelLayout = PanelLayout()) -> PanelPose | None:
    """The pose of the panel of detection ``det`` in ``gray`` (intensities in [0, 1])
    seen through ``model`` (see the module docstring), or ``None`` when it cannot be
    measured (pattern width unknown, a column out of view or hidden, implausible
    geometry)."""
    sigma = det.width
    if not math.isfinite(sigma):
        return None
    head = np.interp(det.x + np.arange(int(math.ceil(sigma)) + 1),
                     np.arange(gray.shape[1]), gray[int(round(det.y))])
    threshold = 0.5 * (float(np.percentile(head, 5)) + float(np.percentile(head, 95)))
    stripe = _second_dark_stripe(head, threshold)
    if stripe is None:
        return None
    points = []
    for x in (det.x + stripe, det.x + layout.barcode_centre * sigma):
        extent = dark_extent(gray, x, det.top, det.bottom, threshold)
        if extent is None:
            return None
        distance = model.distance(x, extent[0], extent[1], layout.pattern_height)
        bearing = float(model.bearing(x))
        points.append(distance * np.array([math.cos(bearing), math.sin(bearing)]))
    along = points[1] - points[0]
    known = (layout.barcode_centre - 0.5 * (p ** 1.5 + p)) * layout.pattern_width
    length = float(np.hypot(*along))
    if not SCALE_RANGE[0] <= length / known <= SCALE_RANGE[1]:
        return None
    t = along / length
    normal = np.array([t[1], -t[0]])
    if float(normal @ points[0]) >= 0:          # the face must look towards the camera
        return None
    u_centre = (layout.width / 2 - layout.margin) / layout.pattern_width
    centre = points[0] + (u_centre - 0.5 * (p ** 1.5 + p)) * layout.pattern_width * t
    return PanelPose((float(centre[0]), float(centre[1])), math.atan2(normal[1], normal[0]))
