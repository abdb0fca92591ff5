"""Planar geometry helpers: angles in radians (counter-clockwise), poses ``(x, y, yaw)``."""

from __future__ import annotations

import numpy as np

#: One foot in metres (Hong et al. 1991 space their route targets 1 ft apart).
FOOT = 0.3048


def wrap_angle(angle):
    """Wrap an angle (radians, scalar or array) into ``(-pi, pi]``."""
    wrapped = np.mod(np.asarray(angle, dtype=np.float64) + np.pi, 2 * np.pi) - np.pi
    wrapped = np.where(wrapped == -np.pi, np.pi, wrapped)
    return float(wrapped) if np.ndim(wrapped) == 0 else wrapped


def to_frame(pose_ref: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Express world ``pose`` in the frame of world ``pose_ref`` (both ``(x, y, yaw)``)."""
    dx, dy = pose[0] - pose_ref[0], pose[1] - pose_ref[1]
    c, s = np.cos(pose_ref[2]), np.sin(pose_ref[2])
    return np.array([c * dx + s * dy, -s * dx + c * dy, wrap_angle(pose[2] - pose_ref[2])])


def bearing_to(pose: np.ndarray, point) -> float:
    """Bearing (radians, CCW from the robot heading, in ``(-pi, pi]``) of a world point."""
    return wrap_angle(np.arctan2(point[1] - pose[1], point[0] - pose[0]) - pose[2])


def finite_pose(pose) -> np.ndarray:
    """``pose`` as a float array ``(x, y, yaw)`` (metres, radians), or a ``ValueError``
    naming it when it is not three finite numbers (a NaN camera pose renders only sky)."""
    try:
        array = np.asarray(pose, dtype=np.float64)
    except (TypeError, ValueError):
        array = np.full(1, np.nan)
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        raise ValueError(f"pose {pose!r} must be three finite numbers (x, y, yaw)")
    return array
