"""Image matching of Shiraishi & Sawasaki's multi-resolution scheme, as pure functions.

* :func:`front_view` and :func:`match_heading`: §3(1): the front image reduced to low
  resolution is correlated (normalised correlation, ``cv2.TM_CCOEFF_NORMED``) with a
  stored low-resolution panorama at every horizontal offset (the panorama wraps); the
  offset of the best match from the panorama's centre, converted to an angle, is the
  deviation of the camera's heading from the direction the panorama was centred on.
  :func:`locate_on_path` takes the best of a path's panoramas as the current place.
* :func:`arrival_scores`: §3(1) "work location arrival decision", Fig. 5: a rectangle
  clipped from the centre of the front image is enlarged or reduced through several
  levels, brought to the stored panoramas' resolution and compared with the target's
  panorama; the best scale says whether the robot is short of (enlarged best), past
  (reduced best) or at the work location.
* :func:`find_template`: §3(2) (2-3): a high-resolution template searched by
  normalised correlation only in a small window around its predicted position, with a
  sub-pixel peak.
* :func:`triangulate`: §3(2): position and heading from the known 3-D coordinates of
  two or more rediscovered points and their apparent directions (bearing and elevation;
  with the camera height known, two points fix the pose), by least squares
  (Levenberg-Marquardt).

Image coordinates are continuous: column ``x`` in ``[0, W)`` with bearing
``pi - 2*pi*x/W`` (radians, CCW from the heading), pixel ``j`` covering ``[j, j + 1)``;
rows likewise, elevation ``vfov/2 - vfov*y/H``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.optimize import least_squares

from homing_gym.geometry import wrap_angle
from homing_gym.render.panorama import column_bearing


def _wrap_pad(image: np.ndarray, pad: int) -> np.ndarray:
    """``image`` with ``pad`` columns of its other end on each side (it is a panorama)."""
    return np.concatenate([image[:, -pad:], image, image[:, :pad]], axis=1)


def _subpixel(scores: np.ndarray, i: int) -> float:
    """Parabolic refinement of the peak at index ``i`` of a 1-D score array (offset in
    ``[-0.5, 0.5]``, 0 at the borders)."""
    if i <= 0 or i >= len(scores) - 1:
        return 0.0
    a, b, c = float(scores[i - 1]), float(scores[i]), float(scores[i + 1])
    den = a - 2 * b + c
    return 0.0 if den >= 0 else float(np.clip(0.5 * (a - c) / den, -0.5, 0.5))


def front_view(panorama: np.ndarray, fov: float) -> np.ndarray:
    """The central ``fov`` radians (at most ``2*pi``: the whole panorama) of columns of a
    panorama (the camera's front image): an even number of columns centred on column
    ``W/2``, all rows."""
    w = panorama.shape[1]
    n = min(max(2, 2 * int(round(fov / (2 * math.pi) * w / 2))), 2 * (w // 2))
    return panorama[:, w // 2 - n // 2:w // 2 + n // 2]


def match_heading(front: np.ndarray, panorama: np.ndarray) -> tuple[float, float]:
    """Where ``front`` (a front view, same height as ``panorama``) fits in ``panorama``
    (grey): ``(deviation, score)``. ``deviation`` (radians, CCW) is the bearing, in the
    panorama's frame, of the centre of ``front``: the camera's heading relative to the
    direction the panorama is centred on. ``score``: the normalised correlation."""
    h, n = front.shape[:2]
    if panorama.shape[0] != h or n > panorama.shape[1]:
        raise ValueError(f"front view {front.shape} must have the panorama's height and "
                         f"at most its columns, panorama {panorama.shape}")
    w = panorama.shape[1]
    padded = _wrap_pad(panorama, n)
    scores = cv2.matchTemplate(padded.astype(np.float32), front.astype(np.float32),
                               cv2.TM_CCOEFF_NORMED)[0]
    i = int(np.argmax(scores))
    column = i + _subpixel(scores, i) + n / 2 - n
    return wrap_angle(column_bearing(column, w)), float(scores[i])


def locate_on_path(front: np.ndarray, panoramas) -> tuple[int, float, float]:
    """The place whose panorama matches ``front`` best: ``(index, deviation, score)``
    (:func:`match_heading` for each)."""
    if len(panoramas) == 0:
        raise ValueError("no stored panoramas to match against")
    matches = [match_heading(front, p) for p in panoramas]
    k = int(np.argmax([s for _, s in matches]))
    return k, matches[k][0], matches[k][1]


def arrival_scores(panorama: np.ndarray, target: np.ndarray, scales, fov: float,
                   levels: int, shift: int = 2) -> np.ndarray:
    """Normalised correlation of the current full-resolution grey ``panorama``'s front,
    enlarged by each of ``scales`` about the image centre (ahead, on the horizon), with
    the target's low-resolution panorama ``target`` (``levels`` pyramid steps smaller).

    The compared rectangle is the central ``fov`` radians and the central half of the
    rows of ``target``; for scale ``s`` the current image's rectangle ``1/s`` times as
    large is resampled to it (``cv2.resize``, area averaging). The best of horizontal
    shifts up to ``shift`` low-resolution columns is taken (residual heading error)."""
    H, W = panorama.shape[:2]
    h, w = target.shape[:2]
    k = 2 ** levels
    half_w = max(1, int(round(fov / (2 * math.pi) * w / 2)))
    half_h = max(1, h // 4)
    ref = target[h // 2 - half_h:h // 2 + half_h,
                 w // 2 - half_w - shift:w // 2 + half_w + shift].astype(np.float32)
    out = []
    for s in scales:
        if not (0.5 <= s <= 2.0):
            raise ValueError(f"arrival scales must lie in [0.5, 2], got {s!r}")
        cw, ch = half_w * k / s, half_h * k / s
        patch = cv2.getRectSubPix(_wrap_pad(panorama, W // 2),
                                  (int(round(2 * cw)), int(round(2 * ch))),
                                  (W / 2 - 0.5 + W // 2, H / 2 - 0.5))
        small = cv2.resize(patch, (2 * half_w, 2 * half_h), interpolation=cv2.INTER_AREA)
        scores = cv2.matchTemplate(ref, small.astype(np.float32), cv2.TM_CCOEFF_NORMED)
        out.append(float(scores.max()))
    return np.array(out)


@dataclass(frozen=True)
class TemplateMatch:
    """A rediscovered characteristic point: continuous ``(x, y)`` of the template's
    centre in the searched image and the normalised correlation ``score``."""

    x: float
    y: float
    score: float


def find_template(image: np.ndarray, template: np.ndarray, x: float, y: float,
                  radius: tuple[int, int]) -> TemplateMatch | None:
    """Search grey ``template`` (odd size ``t``) in the grey panorama ``image`` with its
    centre within ``radius = (columns, rows)`` of the continuous point ``(x, y)`` (columns
    wrap). Rows of the window beyond the image are cut off; where the centre is inside
    the image but the template reaches past its top or bottom, only the template's rows
    inside the image are correlated (a point near the edge of the view is still a point
    in view). ``None`` if no row of the window lies in the image."""
    t = template.shape[0]
    H, W = image.shape[:2]
    rx, ry = radius
    r = t // 2
    cx, cy = int(math.floor(x)), int(math.floor(y))
    first, last = max(cy - ry, 0), min(cy + ry, H - 1)     # rows of the centre
    if first > last:
        return None
    pad = rx + r + 1
    left = cx - rx - r + pad
    strip = _wrap_pad(image, pad)[:, left:left + 2 * rx + t].astype(np.float32)
    template = template.astype(np.float32)
    scores = np.full((last - first + 1, 2 * rx + 1), -np.inf, np.float32)
    inner_first, inner_last = max(first, r), min(last, H - 1 - r)
    if inner_first <= inner_last:                            # the whole template inside
        scores[inner_first - first:inner_last - first + 1] = cv2.matchTemplate(
            strip[inner_first - r:inner_last + r + 1], template, cv2.TM_CCOEFF_NORMED)
    below = min(r, last + 1)                                 # rows cut at the top: [first, below)
    for row in [*range(first, below), *range(max(H - r, first, below), last + 1)]:
        top, bottom = max(row - r, 0), min(row + r + 1, H)  # the template's rows inside
        part = template[top - (row - r):bottom - (row - r)]
        scores[row - first] = cv2.matchTemplate(strip[top:bottom], part,
                                                cv2.TM_CCOEFF_NORMED)[0]
    j, i = np.unravel_index(int(np.argmax(scores)), scores.shape)
    dx = _subpixel(scores[j, :], i)
    dy = _subpixel(scores[:, i], j)
    return TemplateMatch(x=float((cx - rx + i + dx + 0.5) % W), y=float(first + j + dy + 0.5),
                         score=float(scores[j, i]))


def _predicted(pose, points: np.ndarray, camera_height: float) -> np.ndarray:
    dx, dy = points[:, 0] - pose[0], points[:, 1] - pose[1]
    dist = np.hypot(dx, dy)
    return np.concatenate([wrap_angle(np.arctan2(dy, dx) - pose[2]),
                           np.arctan2(points[:, 2] - camera_height, dist)])


def predicted_directions(pose, points, camera_height: float) -> tuple[np.ndarray, np.ndarray]:
    """Bearings and elevations (radians) of 3-D ``points`` ``(N, 3)`` seen from a camera
    at ``pose`` (x, y, yaw), ``camera_height`` metres above the floor."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    both = _predicted(np.asarray(pose, dtype=np.float64), pts, camera_height)
    return both[:len(pts)], both[len(pts):]


def triangulate(points, bearings, elevations, camera_height: float, guess) -> np.ndarray:
    """The camera pose ``(x, y, yaw)`` (metres, radians) that best explains the observed
    ``bearings`` and ``elevations`` (radians) of known 3-D ``points`` ``(N, 3)``, N >= 2:
    least squares on the angle residuals (bearing residuals wrapped to ``(-pi, pi]``) from
    ``guess``, by Levenberg-Marquardt (``scipy.optimize.least_squares(method="lm")``)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(pts) < 2 or len(bearings) != len(pts) or len(elevations) != len(pts):
        raise ValueError(f"triangulation needs at least 2 points with one bearing and one "
                         f"elevation each, got {len(pts)} points, {len(bearings)} bearings, "
                         f"{len(elevations)} elevations")
    observed = np.concatenate([bearings, elevations]).astype(np.float64)

    def residual(q):
        r = _predicted(q, pts, camera_height) - observed
        r[:len(pts)] = wrap_angle(r[:len(pts)])
        return r

    pose = least_squares(residual, np.asarray(guess, dtype=np.float64), method="lm",
                         xtol=1e-12, ftol=1e-12).x
    pose[2] = wrap_angle(pose[2])
    return pose
