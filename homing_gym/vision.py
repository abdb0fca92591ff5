"""Image primitives shared by the env and every controller: luminance, grey levels, the
horizon line of a panorama, the seamless panorama pyramid.

One definition each, so that every method sees the same numbers:

* :func:`luminance`: ITU-R BT.601 luma ``0.299 R + 0.587 G + 0.114 B`` of RGB uint8
  images as float32, in ``[0, 1]`` (``scale=1``) or ``[0, 255]`` (``scale=255``);
* :func:`grey`: the same, rounded to uint8 grey levels;
* :func:`horizon_line`: one luminance value per panorama column, averaged over rows about
  the horizon with given row weights (Hong et al. 1991 §2's signature, Franz et al.
  1998's horizon image);
* :func:`low_resolution`: ``cv2.pyrDown`` steps of a grey panorama, padded with its own
  columns so the reduction is seamless across the 360-degree wrap.
"""

from __future__ import annotations

import cv2
import numpy as np

LUMA = np.array([0.299, 0.587, 0.114], dtype=np.float32)


def luminance(image: np.ndarray, scale: float = 1.0) -> np.ndarray:
    """BT.601 luma of an RGB (or RGBA, alpha ignored) uint8 image ``(..., 3)``, float32,
    ``scale`` for white (1: ``[0, 1]``; 255: grey levels). A 2-D image is taken as grey
    levels already and only rescaled."""
    img = np.asarray(image)
    if img.ndim == 2:
        return (img.astype(np.float32) * np.float32(scale / 255.0)).astype(np.float32)
    if img.shape[-1] not in (3, 4):
        raise ValueError(f"expected an RGB image (..., 3), got shape {img.shape}")
    luma = img[..., :3].astype(np.float32) @ LUMA
    return luma if scale == 255.0 else luma / np.float32(255.0 / scale)


def grey(image: np.ndarray) -> np.ndarray:
    """Grey levels (BT.601 luma, rounded) of an RGB uint8 image, uint8; a grey image as is."""
    if image.ndim == 2:
        return image
    return np.clip(luminance(image, 255.0) + 0.5, 0, 255).astype(np.uint8)


def horizon_line(panorama: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Luminance in ``[0, 1]`` of each column, ``weights @ rows``: float32 ``(W,)``.
    ``weights`` ``(H,)`` mixes the rows (see ``homing_gym.render.panorama.signature_weights``)."""
    return (weights @ luminance(panorama, 255.0)) / np.float32(255.0)


def low_resolution(image: np.ndarray, levels: int) -> np.ndarray:
    """``image`` (RGB or grey uint8) in grey levels, reduced ``levels`` times by
    ``cv2.pyrDown`` (Gaussian smoothing, then every other row and column). A panorama
    wraps around horizontally, so it is padded with its own columns first and cropped
    back, which keeps the reduction seamless at the seam."""
    if not (isinstance(levels, (int, np.integer)) and 0 <= levels <= 5):
        raise ValueError(f"levels must be an integer in [0, 5] pyramid steps, got {levels!r}")
    out = grey(image)
    for _ in range(levels):
        pad = 4
        padded = np.concatenate([out[:, -pad:], out, out[:, :pad]], axis=1)
        out = cv2.pyrDown(padded)[:, pad // 2:pad // 2 + (out.shape[1] + 1) // 2]
    return np.ascontiguousarray(out)


def low_resolution_shape(shape: tuple[int, int], levels: int) -> tuple[int, int]:
    """``(H, W)`` of :func:`low_resolution` for an image of ``shape = (H, W)``."""
    h, w = shape
    for _ in range(levels):
        h, w = (h + 1) // 2, (w + 1) // 2
    return h, w
