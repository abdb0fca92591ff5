"""Self-localisation at a work location (Shiraishi & Sawasaki §3(2), Figs. 2, 9, 10).

:func:`localise` runs the paper's coarse-to-fine procedure on one panorama:

(2-1) reduce the current view to low resolution and correlate its front with the map's
      low-resolution panorama (1-1): the approximate heading;
(2-2) from that heading and the positions (1-3), predict where each characteristic
      point should appear in the current full-resolution view;
(2-3) search each high-resolution template (1-2) by normalised correlation only in a
      small window around its prediction (this also keeps look-alike points, problem
      (b-2), from being confused);

then, with two or more rediscovered points, compute position and heading from their
known 3-D coordinates and apparent directions (:func:`~homing_baselines.multires_matching.triangulate`).

Choices where the paper is silent: the apparent direction of a point is its bearing
*and* its elevation (with the camera height known, two points then fix the pose); the
first windows are ``coarse_radius`` wide because the heading is known only to a
low-resolution column and parallax moves near points; a second pass predicts every
point from the first pose estimate and searches again in ``fine_radius`` windows; a
pose is fitted to the pair of points that most other points agree with (within
``outlier`` radians; all pairs are tried, there are at most 45) and refitted on those, and
a pose more than ``max_offset`` from the work location
is rejected. The view correlated in (2-1) is the whole low-resolution panorama (the
robot's camera sees all around; the paper's robot turned its head instead, Fig. 6).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from homing_baselines.multires_matching import (find_template, front_view, match_heading,
                                         predicted_directions, triangulate)
from homing_gym.geometry import wrap_angle
from homing_gym.panorama import bearing_column, column_bearing, row_elevation
from homing_gym.teaching import FeatureMap
from homing_gym.vision import grey, low_resolution


@dataclass(frozen=True)
class LocaliseConfig:
    """Camera calibration (``camera_height`` m, ``vfov`` rad), the width ``fov`` (rad) of
    the view correlated in (2-1) (default the whole panorama: the robot's camera sees
    all around, where the paper's robot turned its head), search windows (half sizes in full-resolution pixels: columns, rows), the
    normalised-correlation ``threshold`` of a rediscovery, the ``outlier`` residual
    (rad) and ``max_offset`` (m): a pose further than this from the work location is
    rejected as a false rediscovery."""

    camera_height: float = 0.30
    vfov: float = np.radians(60.0)
    fov: float = 2 * np.pi
    coarse_radius: tuple[int, int] = (24, 8)
    fine_radius: tuple[int, int] = (4, 3)
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


def _search(image: np.ndarray, fmap: FeatureMap, columns: np.ndarray, rows: np.ndarray,
            radius: tuple[int, int], threshold: float):
    found = []
    for k, (x, y) in enumerate(zip(columns, rows)):
        match = find_template(image, fmap.templates[k], float(x), float(y), radius)
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
    that most others agree with (within ``outlier``), refitted on all that agree;
    ``(None, [])`` with fewer than two points or a pose beyond ``max_offset``."""
    def solve(subset):
        bearings, elevations = _directions(subset, shape, config.vfov)
        return triangulate(fmap.points[[k for k, _, _ in subset]], bearings, elevations,
                           config.camera_height, guess)

    best: list = []
    for a, b in itertools.combinations(range(len(found)), 2):
        pose = solve([found[a], found[b]])
        inliers = [f for f, e in zip(found, _errors(pose, found, fmap, shape, config))
                   if e <= config.outlier]
        if len(inliers) > len(best):
            best = inliers
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
    found = _search(image, fmap, columns, rows, config.coarse_radius, config.threshold)
    pose, used = _fit(found, fmap, (H, W), config, guess)
    if pose is None:
        return Localisation(None, heading, len(found))
    bearings, elevations = predicted_directions(pose, fmap.points, config.camera_height)
    columns = bearing_column(bearings, W)
    rows = (config.vfov / 2 - elevations) / config.vfov * H
    found = _search(image, fmap, columns, rows, config.fine_radius, config.threshold)
    refined, fine = _fit(found, fmap, (H, W), config, pose)
    if refined is None:
        return Localisation(pose, heading, len(used))
    return Localisation(refined, heading, len(fine))
