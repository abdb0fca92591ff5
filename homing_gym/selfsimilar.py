"""Self-similar landmark patterns with a barcode (Briggs, Scharstein et al. 2000, §2-3.2).

The pattern is the self-similar square wave (Eq. 4-5)

    S(x) = floor(2 (x - floor(x)))        s_p(x) = S(log_p x)

for a scale factor ``0 < p < 1`` (the paper's examples use ``p = 2/3``), made
two-dimensional by keeping it constant in the vertical direction, ``L(x, y) = s_p(x)``
(Eq. 6). ``s_p`` is p-similar, ``s_p(x) = s_p(p x)``, and sqrt(p)-antisimilar,
``s_p(x) = 1 - s_p(sqrt(p) x)``, so ``d_{p,w}(s_p) = 0`` and ``d_{sqrt p,w}(s_p) = 1``
(Eq. 1-2) for any window ``w``.

The paper shows its panel (Fig. 4) but gives no dimensions or barcode layout; our
choices (:class:`PanelLayout`), left to right on a white panel with a white margin:

* the pattern, ``s_p(u)`` for ``u`` in ``(0, 1]`` over ``pattern_width`` metres: the
  self-similarity origin ``u = 0`` (infinitely fine stripes, grey once rendered) at its
  left edge, the coarsest stripe (dark, ``u`` in ``(sqrt(p), 1)``) at its right edge;
* a white gap of ``gap`` metres, much narrower than the coarsest stripe, so that a
  detector can tell where the pattern ends (:mod:`homing_baselines.selfsimilar_detector`);
* the barcode, a column ``barcode_width`` metres wide of ``BARCODE_BANDS`` horizontal
  bands of equal height, top to bottom: a dark guard band, ``ID_BITS`` identity bits
  (most significant first, dark = 1), an even-parity bit and a dark guard band. The
  guard bands let a detector find the barcode's vertical extent in its own column
  (under perspective it differs from the pattern's); the parity bit rejects misreads.

``intensity 0`` is black (the pattern's dark stripes, bits set), ``1`` white; a panel
of reduced ``contrast`` c spans ``[1 - c, 1]`` (the paper's ``c s_p``, §3).

Textures are generated on demand (:func:`panel_texture_path`) as PNGs in a cache
folder, ``$HOMING_GYM_CACHE`` or ``~/.cache/homing_gym`` (one file per id, ``p``,
contrast and resolution; written atomically, so parallel workers may share it).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from homing_gym.validation import is_real, require_positive

#: The paper's scale factor (Fig. 3, Fig. 5).
DEFAULT_P = 2 / 3
#: Identity bits of the barcode.
ID_BITS = 5
#: Bands of the barcode column: guard, ID_BITS bits, parity, guard.
BARCODE_BANDS = ID_BITS + 3
#: Largest id: ``2**ID_BITS - 2``. The all-ones id would be an all-dark column, which any
#: dark area next to a pattern-like texture reads as a valid code (rendered corridors gave
#: such false ids); :func:`decode_barcode` therefore rejects it.
MAX_ID = 2 ** ID_BITS - 2
#: Bumped whenever the drawing changes, so stale cached PNGs are not reused.
TEXTURE_VERSION = 1


def square_wave(x):
    """``S(x)`` of Eq. 4: 0 on ``[n, n + 1/2)``, 1 on ``[n + 1/2, n + 1)``."""
    x = np.asarray(x, dtype=np.float64)
    return np.floor(2 * (x - np.floor(x)))


def check_p(p: float) -> float:
    """``p`` as a float; ``ValueError`` unless ``0 < p < 1``."""
    if not (is_real(p) and 0 < p < 1):
        raise ValueError(f"the self-similarity scale p must lie in (0, 1), got {p!r}")
    return float(p)


def self_similar(x, p: float = DEFAULT_P):
    """``s_p(x) = S(log_p x)`` of Eq. 5 for ``x > 0`` (values 0 or 1)."""
    p = check_p(p)
    x = np.asarray(x, dtype=np.float64)
    if np.any(x <= 0):
        raise ValueError("s_p(x) is defined for x > 0 only")
    return square_wave(np.log(x) / math.log(p))


def barcode_bits(landmark_id: int) -> list[int]:
    """The ``BARCODE_BANDS`` band values of ``landmark_id``, top to bottom (1 = dark):
    guard, the id's ``ID_BITS`` bits (most significant first), even parity, guard."""
    if not (isinstance(landmark_id, (int, np.integer)) and 0 <= landmark_id <= MAX_ID):
        raise ValueError(f"landmark id must be an integer in [0, {MAX_ID}], got {landmark_id!r}")
    bits = [(int(landmark_id) >> (ID_BITS - 1 - i)) & 1 for i in range(ID_BITS)]
    return [1, *bits, sum(bits) % 2, 1]


def decode_barcode(bands) -> int | None:
    """The id encoded by ``BARCODE_BANDS`` band values (1 = dark), or ``None`` when the
    guards or the parity do not check or every band is dark (see :data:`MAX_ID`)."""
    bands = [int(b) for b in bands]
    if (len(bands) != BARCODE_BANDS or bands[0] != 1 or bands[-1] != 1
            or all(bands)):
        return None
    bits = bands[1:1 + ID_BITS]
    if sum(bits) % 2 != bands[1 + ID_BITS]:
        return None
    return int("".join(map(str, bits)), 2)


@dataclass(frozen=True)
class PanelLayout:
    """Physical layout of a landmark panel (metres); see the module docstring.

    The pattern is ``pattern_width`` x ``pattern_height``; the panel adds ``gap``,
    ``barcode_width`` and a white ``margin`` on every side.
    """

    pattern_width: float = 0.5
    pattern_height: float = 0.45
    gap: float = 0.04
    barcode_width: float = 0.12
    margin: float = 0.04

    def __post_init__(self) -> None:
        for name in ("pattern_width", "pattern_height", "gap", "barcode_width", "margin"):
            value = getattr(self, name)
            require_positive(f"PanelLayout.{name}", value, "metres")

    @property
    def width(self) -> float:
        """Panel width (m)."""
        return 2 * self.margin + self.pattern_width + self.gap + self.barcode_width

    @property
    def height(self) -> float:
        """Panel height (m)."""
        return 2 * self.margin + self.pattern_height

    @property
    def barcode_centre(self) -> float:
        """Horizontal position of the barcode column's centre, in pattern widths from the
        self-similarity origin (what a detector needs to find the barcode)."""
        return (self.pattern_width + self.gap + self.barcode_width / 2) / self.pattern_width


def panel_image(landmark_id: int, p: float = DEFAULT_P, layout: PanelLayout = PanelLayout(),
                pixels_per_metre: float = 1200.0, contrast: float = 1.0,
                supersample: int = 4) -> np.ndarray:
    """The panel of ``landmark_id`` as a grey uint8 image (rows top to bottom, columns
    left to right as seen from the front), ``pixels_per_metre`` resolution; each pixel
    is the area average of ``supersample`` x ``supersample`` samples, so the stripes
    near the origin average to grey instead of aliasing."""
    p = check_p(p)
    if not (0 < contrast <= 1):
        raise ValueError(f"contrast must be in (0, 1], got {contrast!r}")
    if not (pixels_per_metre >= 20):
        raise ValueError(f"pixels_per_metre must be >= 20, got {pixels_per_metre!r}")
    bands = barcode_bits(landmark_id)
    n_x = int(round(layout.width * pixels_per_metre))
    n_y = int(round(layout.height * pixels_per_metre))
    # sample positions in metres from the panel's top-left corner
    xs = (np.arange(n_x * supersample) + 0.5) / (supersample * pixels_per_metre)
    ys = (np.arange(n_y * supersample) + 0.5) / (supersample * pixels_per_metre)
    m = layout.margin
    u = (xs - m) / layout.pattern_width                      # pattern coordinate
    v = (ys - m) / layout.pattern_height                     # 0 top .. 1 bottom
    row_in = (v >= 0) & (v < 1)
    dark = np.zeros((ys.size, xs.size), bool)
    in_pattern = (u > 0) & (u <= 1)
    pattern_dark = np.zeros_like(u, dtype=bool)
    pattern_dark[in_pattern] = self_similar(u[in_pattern], p) == 0
    dark |= row_in[:, None] & pattern_dark[None, :]
    bar_lo = m + layout.pattern_width + layout.gap
    in_bar = (xs >= bar_lo) & (xs < bar_lo + layout.barcode_width)
    band = np.clip(np.floor(v * BARCODE_BANDS).astype(int), 0, BARCODE_BANDS - 1)
    band_dark = row_in & (np.asarray(bands)[band] == 1)
    dark |= band_dark[:, None] & in_bar[None, :]
    img = np.where(dark, 1.0 - contrast, 1.0)
    img = img.reshape(n_y, supersample, n_x, supersample).mean(axis=(1, 3))
    return np.clip(np.round(255 * img), 0, 255).astype(np.uint8)


def cache_dir() -> Path:
    """Folder of generated textures: ``$HOMING_GYM_CACHE`` or ``~/.cache/homing_gym``."""
    root = os.environ.get("HOMING_GYM_CACHE") or os.path.join(
        os.path.expanduser("~"), ".cache", "homing_gym")
    return Path(root) / "textures"


def panel_texture_path(landmark_id: int, p: float = DEFAULT_P,
                       layout: PanelLayout = PanelLayout(), contrast: float = 1.0,
                       pixels_per_metre: float = 1200.0) -> str:
    """Path of the PNG texture of a panel (generated into :func:`cache_dir` on first
    use), for a ``"panel"`` landmark (:class:`homing_gym.scenes.Landmark`)."""
    img = panel_image(landmark_id, p, layout, pixels_per_metre, contrast)
    key = (f"selfsimilar_v{TEXTURE_VERSION}_id{landmark_id}_p{p:.4f}_c{contrast:.3f}_"
           f"{layout.pattern_width:.3f}x{layout.pattern_height:.3f}_"
           f"g{layout.gap:.3f}_b{layout.barcode_width:.3f}_m{layout.margin:.3f}_"
           f"r{pixels_per_metre:.0f}.png")
    folder = cache_dir()
    path = folder / key
    if not path.is_file():
        folder.mkdir(parents=True, exist_ok=True)
        tmp = folder / f".{key}.{os.getpid()}.png"
        cv2.imwrite(str(tmp), np.repeat(img[:, :, None], 3, axis=2))
        os.replace(tmp, path)
    return str(path)
