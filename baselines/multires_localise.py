"""Self-localisation at a work location (Shiraishi & Sawasaki §3(2), Figs. 2, 9, 10).

:func:`localise` runs the paper's coarse-to-fine procedure on one panorama:

(2-1) reduce the current view to low resolution and correlate its front with the map's
      low-resolution panorama (1-1): the approximate heading;
(2-2) from that heading and the positions (1-3), predict where each characteristic
      point should appear in the current full-resolution view;
(2-3) search each high-resolution template (1-2) by normalised correlation only in a
      window around its prediction (this also keeps look-alike points, problem (b-2),
      from being confused);

then, with two or more rediscovered points, compute position and heading from their
known 3-D coordinates and apparent directions (:func:`~homing_baselines.multires_matching.triangulate`).

Choices where the paper is silent (§3(2) gives no window sizes, scales or robust
estimator; §4(2-2) claims < 10 cm and < 2 deg "within 50 centimeters" of the taught
point, so the search is sized for that range, ``reach`` = 0.5 m):

* the apparent direction of a point is its bearing *and* its elevation (with the
  camera height known, two points then fix the pose);
* (2-3) windows: the prediction (2-2) is exact only at the taught point; from anywhere
  within ``reach`` a point at distance ``d`` appears up to ``asin(reach/d)`` away in
  bearing and correspondingly in elevation (parallax, :func:`parallax_windows`: about
  +-45 columns for a point 1 m away, +-16 for one 3.5 m away), plus ``heading_margin``
  for the error of the low-resolution heading (2-1) (parallax moves the whole view too:
  within 0.5 m of the ``house``'s work locations that heading was off by a median 2.6-4.9
  deg and at most 13.7 deg, so the default is 15 deg) and ``margin`` pixels; and up to
  ``d/(d-reach)`` times larger or ``d/(d+reach)``
  smaller, so each template is also tried at the powers of 2^(1/4) in that range
  (:func:`search_scales`; the paper's own arrival decision, Fig. 5, compares enlarged
  and reduced images the same way) and the best correlation counts; where an enlarged
  template reaches past the image's top or bottom edge, its rows inside the image are
  correlated (:func:`~homing_baselines.multires_matching.find_template`: the nearest
  pictures, half a metre away, appear at the top edge of the 60 deg view);
* the pose is fitted to the pair of points that most others agree with (within
  ``outlier`` radians; all pairs are tried, there are at most 45; among equally many,
  the smallest sum of residuals) and refitted on those; a pose more than
  ``max_offset`` from the work location is rejected;
* ``fine_passes`` times, every point is predicted from the last pose, its template
  resized to the size it has from there (taught over predicted distance), and searched
  again in ``fine_radius`` windows; the pose is refitted on what is found (the paper's
  robot kept tracking its points, Figs. 6-7);
* the view correlated in (2-1) is the whole low-resolution panorama (the robot's
  camera sees all around; the paper's robot turned its head instead, Fig. 6).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import cv2
import numpy as np

from homing_baselines.multires_matching import (find_template, front_view, match_heading,
                                         predicted_directions, triangulate)
from homing_gym.geometry import wrap_angle
from homing_gym.render.panorama import bearing_column, column_bearing, row_elevation
from homing_gym.teaching import FeatureMap
from homing_gym.vision import grey, low_resolution


@dataclass(frozen=True)
class LocaliseConfig:
    """Camera calibration (``camera_height`` m, ``vfov`` rad), the width ``fov`` (rad) of
    the view correlated in (2-1) (default the whole panorama: the robot's camera sees
    all around, where the paper's robot turned its head), ``reach`` (m): how far from
    the work location the robot may stand (it sizes the first windows and scales),
    ``heading_margin`` (rad): how far off the coarse heading (2-1) may be, ``margin``
    and ``fine_radius`` (half sizes in full-resolution pixels: columns,
    rows), ``fine_passes``, the normalised-correlation ``threshold`` of a
    rediscovery, the ``outlier`` residual (rad) and ``max_offset`` (m): a pose further
    than this from the work location is rejected as a false rediscovery."""

    camera_height: float = 0.30
    vfov: float = np.radians(60.0)
    fov: float = 2 * np.pi
    reach: float = 0.5
    heading_margin: float = np.radians(15.0)
    margin: tuple[int, int] = (4, 2)
    fine_radius: tuple[int, int] = (4, 3)
    fine_passes: int = 3
    threshold: float = 0.6
    outlier: float = np.radians(1.5)
    max_offset: float = 0.75


@dataclass(frozen=True)
class Localisation:
    """Result of :func:`localise`: ``pose`` (x, y, yaw; indoor frame, m and rad) or
    ``None`` when fewer than two points were rediscovered; ``heading``: the coarse
    heading (2-1) relative to the map's (rad); ``found``: points used."""

    pose: np.ndarray | None
    heading: float
    found: int


def _distances(fmap: FeatureMap, xy) -> np.ndarray:
    """Horizontal distance (m) of each characteristic point from ``xy``."""
    return np.hypot(*(fmap.points[:, :2] - np.asarray(xy, np.float64)[:2]).T)


def parallax_windows(fmap: FeatureMap, shape, config: LocaliseConfig) -> np.ndarray:
    """Half sizes ``(N, 2)`` (full-resolution columns, rows) of the first (2-3) search
    windows: how far each point's image can move from its taught position (1-3) when the
    robot stands anywhere within ``reach`` metres of the work location, plus
    ``heading_margin`` in bearing and ``margin``."""
    H, W = shape
    d = _distances(fmap, fmap.pose)
    rise = fmap.points[:, 2] - config.camera_height
    near = np.maximum(d - config.reach, 0.5 * d)
    bearing = np.arcsin(np.minimum(1.0, config.reach / d))
    elevation = np.maximum(np.abs(np.arctan2(rise, near) - np.arctan2(rise, d)),
                           np.abs(np.arctan2(rise, d + config.reach) - np.arctan2(rise, d)))
    return np.column_stack([np.ceil((bearing + config.heading_margin) * W / (2 * np.pi))
                            + config.margin[0],
                            np.ceil(elevation * H / config.vfov) + config.margin[1]]).astype(int)


def search_scales(fmap: FeatureMap, config: LocaliseConfig) -> list[list[float]]:
    """For each point, the enlargements 2^(k/4) (k = -4..4) its template is tried at in
    the first search: every size it can appear at from ``reach`` metres further away to
    ``reach`` closer (at most twice as close) is within half a step of one of them."""
    d = _distances(fmap, fmap.pose)
    steps = 2.0 ** (np.arange(-4, 5) / 4)
    half = 2.0 ** (1 / 8)
    return [[float(s) for s in steps
             if dist / (dist + config.reach) / half <= s
             <= dist / max(dist - config.reach, dist / 2) * half]
            for dist in d]


def resized(template: np.ndarray, scale: float) -> np.ndarray:
    """``template`` enlarged ``scale`` times about its centre, to the nearest odd size."""
    size = 2 * int(round(template.shape[0] * scale / 2)) + 1
    if size == template.shape[0]:
        return template
    interpolation = cv2.INTER_AREA if size < template.shape[0] else cv2.INTER_LINEAR
    return cv2.resize(template, (size, size), interpolation=interpolation)


def _search(image: np.ndarray, templates: list[list[np.ndarray]], columns, rows,
            radius, threshold: float) -> list[tuple[int, float, float]]:
    """``[(point index, x, y)]`` of the points whose best template (of each point's
    ``templates``) correlates at least ``threshold`` within ``radius`` (one ``(columns,
    rows)`` or one per point) of its predicted ``(columns, rows)``."""
    found = []
    radii = np.broadcast_to(np.asarray(radius, int), (len(columns), 2))
    for k, (x, y) in enumerate(zip(columns, rows)):
        matches = [m for m in (find_template(image, t, float(x), float(y), tuple(radii[k]))
                               for t in templates[k]) if m is not None]
        match = max(matches, key=lambda m: m.score, default=None)
        if match is not None and match.score >= threshold:
            found.append((k, match.x, match.y))
    return found


def _directions(found, shape, vfov: float) -> tuple[np.ndarray, np.ndarray]:
    H, W = shape
    return (column_bearing(np.array([x for _, x, _ in found]), W),
            row_elevation(np.array([y for _, _, y in found]), H, vfov))


def _errors(pose, found, fmap: FeatureMap, shape, config: LocaliseConfig) -> np.ndarray:
    """Largest of bearing and elevation residual (rad) of each found point at ``pose``."""
    bearings, elevations = _directions(found, shape, config.vfov)
    pb, pe = predicted_directions(pose, fmap.points[[k for k, _, _ in found]],
                                  config.camera_height)
    return np.maximum(np.abs(wrap_angle(pb - bearings)), np.abs(pe - elevations))


def _fit(found, fmap: FeatureMap, shape, config: LocaliseConfig, guess):
    """Triangulate from ``found`` = [(point index, x, y)]: the pose of the pair of points
    that most others agree with (within ``outlier``; among equally many, the smallest
    sum of residuals), refitted on all that agree; ``(None, [])`` with fewer than two
    points or a pose beyond ``max_offset``."""
    def solve(subset):
        bearings, elevations = _directions(subset, shape, config.vfov)
        return triangulate(fmap.points[[k for k, _, _ in subset]], bearings, elevations,
                           config.camera_height, guess)

    best: list = []
    best_key = (0, 0.0)
    for a, b in itertools.combinations(range(len(found)), 2):
        errors = _errors(solve([found[a], found[b]]), found, fmap, shape, config)
        agree = errors <= config.outlier
        key = (int(np.sum(agree)), -float(np.sum(errors[agree])))
        if key > best_key:
            best, best_key = [f for f, ok in zip(found, agree) if ok], key
    if len(best) < 2:
        return None, []
    pose = solve(best)
    if np.hypot(*(pose[:2] - fmap.pose[:2])) > config.max_offset:
        return None, []
    return pose, best


def localise(panorama: np.ndarray, fmap: FeatureMap,
             config: LocaliseConfig = LocaliseConfig()) -> Localisation:
    """Self-localisation from one full-resolution panorama (RGB or grey) against the
    feature map of a work location (module docstring)."""
    image = grey(panorama)
    H, W = image.shape[:2]
    scale = 2 ** fmap.levels
    low = low_resolution(image, fmap.levels)
    heading, _ = match_heading(front_view(low, config.fov), fmap.panorama)
    columns = (fmap.template_xy[:, 0] * scale + heading * W / (2 * np.pi)) % W
    rows = fmap.template_xy[:, 1] * scale
    guess = np.array([fmap.pose[0], fmap.pose[1], fmap.pose[2] + heading], np.float64)
    templates = [[resized(t, s) for s in scales]
                 for t, scales in zip(fmap.templates, search_scales(fmap, config))]
    found = _search(image, templates, columns, rows, parallax_windows(fmap, (H, W), config),
                    config.threshold)
    pose, used = _fit(found, fmap, (H, W), config, guess)
    if pose is None:
        return Localisation(None, heading, len(found))
    for _ in range(config.fine_passes):
        bearings, elevations = predicted_directions(pose, fmap.points, config.camera_height)
        columns = bearing_column(bearings, W)
        rows = (config.vfov / 2 - elevations) / config.vfov * H
        ratios = _distances(fmap, fmap.pose) / _distances(fmap, pose)
        templates = [[resized(t, r)] for t, r in zip(fmap.templates, ratios)]
        found = _search(image, templates, columns, rows, config.fine_radius, config.threshold)
        refined, fine = _fit(found, fmap, (H, W), config, pose)
        if refined is None:
            break
        pose, used = refined, fine
    return Localisation(pose, heading, len(used))
