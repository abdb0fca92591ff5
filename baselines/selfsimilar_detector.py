"""Detecting self-similar landmarks in any image (Briggs, Scharstein et al. 2000, §3).

The pattern (:mod:`homing_gym.selfsimilar`) is ``p``-similar and ``sqrt(p)``-antisimilar
along every non-vertical scanline, so its self-similarity origin is where the match
function of Eq. 7,

    m_y(x) = 1/w sum_xi |I(x+xi, y) - I(x+sqrt(p) xi, y)| - 1/w sum_xi |I(x+xi, y) - I(x+p xi, y)|,

peaks (``xi = 0 .. w-1``, intensities in ``[0, 1]``, in-between pixels by linear
interpolation, §3). The algorithm:

1. ``m_y`` on every ``k``-th scanline (:func:`match_function`); a *match* is a local
   maximum above ``c_min`` that is *sharp*: ``m_y(x_m +- delta) < m_y(x_m)/2`` with
   ``delta ~ w/10`` (§3.1).
2. Matches on consecutive scanlines (``k`` rows apart, at most ``max_shift * k``
   columns apart) are chained; each chain of ``>= 3`` gets a least-squares line
   ``x = a y + b``, the pattern's left edge (§3.2).
3. The vertical extent: the paper estimates it "from the intensity distribution"
   without details; we walk along the fitted line row by row, up and down from the
   outermost matches, while ``m_y`` on the line (best of three columns) stays above
   half the chain's median peak. The edges lie halfway between the last row that
   passes and the first that fails.
4. The barcode (:func:`homing_gym.selfsimilar.barcode_bits`): the pattern's apparent
   width ``sigma`` is the largest dark-to-bright edge on the middle scanline whose
   preceding stripe edges keep the ratio ``sqrt(p)`` and which is followed by the white
   gap (the self-similar pattern alone cannot tell ``sigma`` from ``p sigma``; the
   narrow gap can).
   The barcode column is then ``layout.barcode_centre * sigma`` to the right of the
   origin; its guard bands give its vertical extent (under perspective it differs from
   the pattern's), and each band is read at its centre. A detection whose guards or
   parity do not check has ``id = None`` and is dropped when ``require_id``.

§3.3's speed-ups are options: ``coarse_rows`` (every ``2k``-th scanline first, its
neighbours only where it matched) and ``peak_step = l`` (``m_y`` only at every
``l``-th pixel; around samples above ``h = c_min/4`` it is evaluated densely).

The result gives each landmark's id, image position, bearing, apparent size and the
horizontal distance from its apparent height (§4.1) through a camera model
(:mod:`homing_baselines.camera_models`), so it runs on perspective images and on the
panorama alike (columns wrap around in a panorama).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from numba import njit

from homing_baselines.camera_models import CameraModel
from homing_gym.geometry import wrap_angle
from homing_gym.vision import LUMA, luminance
from homing_gym.selfsimilar import (BARCODE_BANDS, DEFAULT_P, PanelLayout, check_p,
                                    decode_barcode)


@dataclass(frozen=True)
class DetectorConfig:
    """Detector parameters (pixels unless named otherwise).

    ``window`` w and ``row_step`` k: the paper's typical values for 640 x 480 are 45 and 6
    (§3); both depend only on the smallest expected landmark (its pattern must be at least
    about ``w`` pixels wide and ``3k`` rows tall). ``min_peak`` c_min: a fixed threshold
    "corresponding to a minimum contrast" (§3.1), the paper gives no number. A pattern of
    image contrast c answers ``m = c`` at best (§3, Eq. 7), less once sampled: ours
    measure 0.6 c on synthetic scanlines (the paper's 0.66, §3.1) and about 0.42 c in
    rendered 320 x 240 views with w = 22, where a white panel under the scene's light
    renders at 0.6, so full contrast gives peaks of 0.25 and contrast 0.25 peaks of
    0.065. Hence 0.04: patterns down to about 0.1 of image contrast; the sharpness
    test and the chains of §3.2 keep the false positives down (an earlier 0.2 rejected
    every panel below half contrast, in the match, not in the barcode). ``sharpness`` gives
    ``delta = max(1, round(sharpness * w))``: the paper says about w/10, but with the
    origin between pixels our 2/3-similar peaks are still at 0.55-0.7 of their height
    at +-w/10 and fall below half only at +-w/7.5 (6 pixels for w = 45), while a
    3/4-similar wave (Fig. 5d) stays above 0.8 there; hence 0.13. ``coarse_rows`` and
    ``peak_step`` are §3.3's speed-ups (``peak_step`` 1 = off; the paper suggests 4-5,
    even 10). ``layout`` is the panel design, known to the robot (pattern height for the
    distance, barcode position for the id).
    """

    p: float = DEFAULT_P
    window: int = 45
    row_step: int = 6
    min_peak: float = 0.04
    sharpness: float = 0.13
    coarse_rows: bool = False
    peak_step: int = 1
    min_group: int = 3
    max_shift: float = 1.0
    require_id: bool = True
    layout: PanelLayout = field(default_factory=PanelLayout)

    def __post_init__(self) -> None:
        check_p(self.p)
        for name, low in (("window", 4), ("row_step", 1), ("peak_step", 1), ("min_group", 2)):
            value = getattr(self, name)
            if not (isinstance(value, (int, np.integer)) and value >= low):
                raise ValueError(f"DetectorConfig.{name} must be an integer >= {low}, "
                                 f"got {value!r}")
        if not (0 < self.min_peak < 1):
            raise ValueError(f"DetectorConfig.min_peak must be in (0, 1), got {self.min_peak!r}")
        if not (0 < self.sharpness < 0.5):
            raise ValueError(f"DetectorConfig.sharpness must be in (0, 0.5), "
                             f"got {self.sharpness!r}")
        if not (self.max_shift >= 0):
            raise ValueError(f"DetectorConfig.max_shift must be >= 0, got {self.max_shift!r}")

    @property
    def delta(self) -> int:
        """Half-height test offset of §3.1 (pixels)."""
        return max(1, int(round(self.sharpness * self.window)))


@dataclass(frozen=True)
class Detection:
    """One landmark found in an image (pixel-index coordinates; see
    :mod:`homing_baselines.camera_models`).

    ``x``, ``y``: the pattern's self-similarity origin (its left edge) on the middle row
    of the extent; ``top``, ``bottom``: rows of the pattern's edges on that line;
    ``slope``: ``dx/dy`` of the fitted line; ``width``: apparent pattern width sigma
    (pixels, on the middle row; ``nan`` if not measured); ``centre_x``: column of the
    centre of pattern + gap + barcode; ``bearing`` (radians, CCW from the heading) of
    ``centre_x``; ``distance``: horizontal distance (m) of the pattern's left edge from
    its apparent height; ``strength``: median peak value of its matches; ``matches``:
    how many scanlines matched.
    """

    id: int | None
    x: float
    y: float
    top: float
    bottom: float
    slope: float
    width: float
    centre_x: float
    bearing: float
    distance: float
    strength: float
    matches: int

    @property
    def height(self) -> float:
        """Apparent pattern height (pixels)."""
        return self.bottom - self.top


def to_gray(image: np.ndarray) -> np.ndarray:
    """Luminance in ``[0, 1]`` (float32) of a uint8 RGB(A) or grey image: BT.601 luma,
    as :func:`homing_gym.vision.luminance` but compiled, ``(0.299 r + 0.587 g + 0.114 b)
    / 255`` in float32 left to right (numpy's matrix product may round the last bit
    differently: values differ by at most 2e-8)."""
    img = np.asarray(image)
    if img.ndim != 3 or img.dtype != np.uint8:
        return luminance(img)
    if img.shape[-1] not in (3, 4):
        raise ValueError(f"expected an RGB image (..., 3), got shape {img.shape}")
    return _luma(np.ascontiguousarray(img[..., :3]), *LUMA)


@njit(cache=True)
def _luma(img, r, g, b):
    """Luma of a C-contiguous ``(H, W, 3)`` uint8 image (the constant stride 3 lets the
    compiler vectorise the loop)."""
    out = np.empty(img.shape[:2], np.float32)
    flat, dest = img.reshape(-1), out.reshape(-1)
    for i in range(dest.size):
        dest[i] = (np.float32(flat[3 * i]) * r + np.float32(flat[3 * i + 1]) * g
                   + np.float32(flat[3 * i + 2]) * b) / np.float32(255.0)
    return out


@lru_cache(maxsize=32)
def _taps(p: float, w: int) -> tuple[np.ndarray, ...]:
    """The interpolation taps of Eq. 7 for ``xi = 1 .. w-1``: ``xi``; floor ``a`` of
    ``sqrt(p) xi`` and its two weights ``1 - f``, ``f`` (float32); floor ``b`` of ``p xi``
    and its two weights. (``xi = 0`` adds nothing: both differences are 0.)"""
    xi = np.arange(1, w, dtype=np.int64)
    s, q = math.sqrt(p) * xi, p * xi
    a, b = s.astype(np.int64), q.astype(np.int64)
    fa, fb = s - a, q - b
    f32 = np.float32
    return (xi, a, (1 - fa).astype(f32), fa.astype(f32), b, (1 - fb).astype(f32),
            fb.astype(f32))


# The kernels below are compiled with numba (cached on disk). Their arithmetic is float32
# and in the order of Eq. 7 (for each xi: |I(x+xi) - I(x+sqrt(p) xi)| - |I(x+xi) - I(x+p xi)|,
# summed over xi, divided by w), the same as numpy's on float32 arrays, so the values
# and every decision taken on them are those of a plain numpy implementation.
@njit(cache=True)
def _m_at(row, x, w, xi, a, wa0, wa1, b, wb0, wb1):
    """``m_y(x)`` of Eq. 7 on one scanline ``row`` (float32) at integer ``x``."""
    acc = np.float32(0.0)
    for t in range(xi.size):
        base = row[x + xi[t]]
        similar = row[x + b[t]] * wb0[t] + row[x + b[t] + 1] * wb1[t]
        anti = row[x + a[t]] * wa0[t] + row[x + a[t] + 1] * wa1[t]
        acc += abs(base - anti) - abs(base - similar)
    return acc / np.float32(w)


@njit(cache=True)
def _m_strided(row, n, step, w, xi, a, wa0, wa1, b, wb0, wb1):
    """``m_y(x)`` at ``x = 0, step, .. (n-1) step`` (taps outer, positions inner: the
    inner loop is vectorised by the compiler)."""
    acc = np.zeros(n, np.float32)
    for t in range(xi.size):
        o, oa, ob = xi[t], a[t], b[t]
        ca0, ca1, cb0, cb1 = wa0[t], wa1[t], wb0[t], wb1[t]
        for i in range(n):
            x = i * step
            base = row[x + o]
            similar = row[x + ob] * cb0 + row[x + ob + 1] * cb1
            anti = row[x + oa] * ca0 + row[x + oa + 1] * ca1
            acc[i] += abs(base - anti) - abs(base - similar)
    for i in range(n):
        acc[i] = acc[i] / np.float32(w)
    return acc


@njit(cache=True)
def _m_rows(rows, step, w, xi, a, wa0, wa1, b, wb0, wb1):
    nx = rows.shape[1] - w + 1
    n = (nx + step - 1) // step
    out = np.zeros((rows.shape[0], n), np.float32)
    for r in range(rows.shape[0]):
        out[r] = _m_strided(rows[r], n, step, w, xi, a, wa0, wa1, b, wb0, wb1)
    return out


@njit(cache=True)
def _m_points(gray, ys, xs, w, xi, a, wa0, wa1, b, wb0, wb1):
    out = np.full(xs.size, np.float32(-1.0))
    for i in range(xs.size):
        x, y = xs[i], ys[i]
        if x >= 0 and x + w <= gray.shape[1] and y >= 0 and y < gray.shape[0]:
            out[i] = _m_at(gray[y], x, w, xi, a, wa0, wa1, b, wb0, wb1)
    return out


def match_function(rows: np.ndarray, p: float = DEFAULT_P, w: int = 45,
                   step: int = 1) -> np.ndarray:
    """``m_y(x)`` of Eq. 7 for each row of ``rows`` (``(R, n)`` intensities in [0, 1])
    at ``x = 0, step, 2 step, ...`` up to ``n - w``: ``(R, ceil((n - w + 1)/step))``."""
    rows = np.ascontiguousarray(np.atleast_2d(np.asarray(rows, dtype=np.float32)))
    if rows.shape[1] - w + 1 <= 0:
        return np.zeros((rows.shape[0], 0), np.float32)
    return _m_rows(rows, step, w, *_taps(p, w))


def match_points(gray: np.ndarray, ys, xs, p: float = DEFAULT_P, w: int = 45) -> np.ndarray:
    """``m_y(x)`` of Eq. 7 at integer points ``(xs, ys)``; ``-1`` where the window
    leaves the image."""
    xs = np.asarray(xs, dtype=np.int64)
    ys = np.broadcast_to(np.asarray(ys, dtype=np.int64), xs.shape)
    out = _m_points(np.ascontiguousarray(gray, dtype=np.float32), ys.ravel(), xs.ravel(), w,
                    *_taps(p, w))
    return out.reshape(xs.shape)


@dataclass
class _Match:
    row: int      # index into the scanline list
    y: int
    x: float
    value: float


@njit(cache=True)
def _row_peaks(row, step, min_peak, delta, x_limit, w, xi, a, wa0, wa1, b, wb0, wb1):
    """The sharp peaks of ``m_y`` on one scanline (§3.1, §3.3): positions (sub-pixel,
    float64) and values. ``m_y`` is evaluated at every ``step``-th column, then densely
    within ``step`` of every sample above ``min_peak / 4``; a peak is a sample at least
    its left and above its right neighbour (unevaluated: -inf), above ``min_peak`` and
    left of ``x_limit``, whose values ``delta`` either side (evaluated when needed) are
    below half its own."""
    taps = (w, xi, a, wa0, wa1, b, wb0, wb1)
    nx = row.size - w + 1
    xs_out = np.empty(0, np.float64)
    vs_out = np.empty(0, np.float32)
    if nx <= 2:
        return xs_out, vs_out
    values = np.full(nx, np.float32(np.nan))
    n = (nx + step - 1) // step
    coarse = _m_strided(row, n, step, *taps)
    for i in range(n):
        values[i * step] = coarse[i]
    if step > 1:
        low = min_peak / np.float32(4.0)
        todo = np.zeros(nx, np.bool_)
        hit = False
        for i in range(n):
            if coarse[i] >= low:
                hit = True
                for x in range(max(0, i * step - step), min(nx, i * step + step + 1)):
                    todo[x] = True
        if not hit:
            return xs_out, vs_out
        for x in range(nx):
            if todo[x] and np.isnan(values[x]):
                values[x] = _m_at(row, x, *taps)
    v = values.copy()
    for x in range(nx):
        if np.isnan(v[x]):
            v[x] = -np.inf
    xs_list, vs_list = [], []
    for x in range(1, min(nx - 1, x_limit)):
        value = v[x]
        if not (value >= v[x - 1] and value > v[x + 1] and value > min_peak):
            continue
        sharp = True
        for side in (x - delta, x + delta):
            around = -np.inf
            if 0 <= side < nx:
                around = values[side]
                if np.isnan(around):
                    around = _m_at(row, side, *taps)
            if not (around < np.float64(value) / 2.0):
                sharp = False
        if not sharp:
            continue
        # sub-pixel position from a parabola through the peak and its neighbours
        denom = v[x - 1] - np.float32(2.0) * value + v[x + 1]
        offset = np.float32(0.0)
        if np.isfinite(denom) and denom < 0:
            offset = np.float32(0.5) * (v[x - 1] - v[x + 1]) / denom
            offset = min(max(offset, np.float32(-0.5)), np.float32(0.5))
        xs_list.append(np.float64(x) + np.float64(offset))
        vs_list.append(value)
    if len(xs_list):
        xs_out = np.array(xs_list)
        vs_out = np.array(vs_list)
    return xs_out, vs_out


@njit(cache=True)
def _rows_peaks(gray, ys, step, min_peak, delta, x_limit, w, xi, a, wa0, wa1, b, wb0, wb1):
    """:func:`_row_peaks` on scanlines ``ys`` of ``gray``: ``(index into ys, x, value)``
    of every peak, in one compiled call."""
    rows, xs, vs = [], [], []
    for r in range(ys.size):
        px, pv = _row_peaks(gray[ys[r]], step, min_peak, delta, x_limit, w, xi, a, wa0, wa1,
                            b, wb0, wb1)
        for j in range(px.size):
            rows.append(r)
            xs.append(px[j])
            vs.append(pv[j])
    return np.array(rows, np.int64), np.array(xs, np.float64), np.array(vs, np.float32)


def _row_matches(gray: np.ndarray, ys: list[int], cfg: DetectorConfig,
                 x_limit: int) -> list[list[_Match]]:
    """For each scanline ``y`` of ``ys``: the sharp local maxima above ``c_min`` of ``m_y``
    with ``x < x_limit`` (§3.1), with the §3.3 peak scan every ``peak_step`` pixels."""
    found: list[list[_Match]] = [[] for _ in ys]
    if not ys:
        return found
    rows, xs, vs = _rows_peaks(gray, np.asarray(ys, np.int64), cfg.peak_step,
                               np.float32(cfg.min_peak), cfg.delta, int(x_limit), cfg.window,
                               *_taps(cfg.p, cfg.window))
    for r, x, v in zip(rows.tolist(), xs.tolist(), vs.tolist()):
        found[r].append(_Match(-1, ys[r], x, v))
    return found


def _scan(gray: np.ndarray, cfg: DetectorConfig, x_limit: int) -> list[list[_Match]]:
    """Matches per scanline ``k/2, k/2 + k, ...``; with ``coarse_rows`` every second
    scanline first and the others only next to a scanline that matched (§3.3)."""
    ys = list(range(cfg.row_step // 2, gray.shape[0], cfg.row_step))
    found: list[list[_Match]] = [[] for _ in ys]
    first = list(range(0, len(ys), 2) if cfg.coarse_rows else range(len(ys)))
    for i, row in zip(first, _row_matches(gray, [ys[i] for i in first], cfg, x_limit)):
        found[i] = row
    if cfg.coarse_rows:
        second = [i for i in range(1, len(ys), 2)
                  if found[i - 1] or (i + 1 < len(ys) and found[i + 1])]
        for i, row in zip(second, _row_matches(gray, [ys[i] for i in second], cfg, x_limit)):
            found[i] = row
    for i, row in enumerate(found):
        for m in row:
            m.row = i
    return found


def _chains(rows: list[list[_Match]], cfg: DetectorConfig) -> list[list[_Match]]:
    """Chains of matches on consecutive scanlines, each match joined to the nearest
    unclaimed match of the scanline above within ``max_shift * k + 1`` columns."""
    tol = cfg.max_shift * cfg.row_step + 1
    chains: list[list[_Match]] = []
    open_chains: dict[int, list[_Match]] = {}       # id(last match) -> chain
    previous: list[_Match] = []
    for row in rows:
        claimed: set[int] = set()
        current: dict[int, list[_Match]] = {}
        for m in row:
            best = None
            for q in previous:
                if id(q) in claimed or abs(q.x - m.x) > tol:
                    continue
                if best is None or abs(q.x - m.x) < abs(best.x - m.x):
                    best = q
            if best is None:
                chain = [m]
                chains.append(chain)
            else:
                claimed.add(id(best))
                chain = open_chains[id(best)]
                chain.append(m)
            current[id(m)] = chain
        open_chains, previous = current, row
    return [c for c in chains if len(c) >= cfg.min_group]


@njit(cache=True)
def _walk(gray, y, direction, limit, a, b, level, w, xi, ta, wa0, wa1, tb, wb0, wb1):
    """The last row reached from row ``y`` moving by ``direction`` (at most ``limit``
    rows) while ``m_y`` on the line ``x = a y + b`` (best of the three nearest columns)
    stays at or above ``level``."""
    for _ in range(limit):
        nxt = y + direction
        if not (0 <= nxt < gray.shape[0]):
            break
        x = int(np.rint(a * nxt + b))
        best = np.float32(-1.0)
        for c in range(x - 1, x + 2):
            if c >= 0 and c + w <= gray.shape[1]:
                best = max(best, _m_at(gray[nxt], c, w, xi, ta, wa0, wa1, tb, wb0, wb1))
        if not (np.float64(best) >= level):
            break
        y = nxt
    return y


# The per-chain steps below (§3.2: line, extent, pattern width, barcode) are compiled
# too, one call per frame for all chains. They keep the arithmetic of the numpy
# formulation they replace: np.interp's float64 ``(right - left) t + left`` rounded to
# float32; np.percentile's "linear" method (float32 difference, float64 weight);
# comparisons and edge offsets in float32 with the threshold rounded to float32 (numpy 2
# casts a Python float to the array's type); the barcode column's mean of three samples
# as ``(c0 + c1) + c2`` and each band's sum as numpy's add.reduce does it (first element
# plus the pairwise sum of the rest), so every decision is the same.
@njit(cache=True)
def _line(ys, xs):
    """Least-squares line ``x = a y + b`` through the matches (§3.2): ``(a, b)``."""
    my, mx = ys.mean(), xs.mean()
    dy = ys - my
    a = (dy * (xs - mx)).sum() / (dy * dy).sum()
    return a, mx - a * my


@njit(cache=True)
def _profile(row, x0):
    """Row ``row`` at columns ``x0, x0 + 1, ...`` up to the image's last column (float32;
    linear interpolation, the end values beyond the row)."""
    n = max(0, int(math.ceil(row.size - x0 - 1)))
    out = np.empty(n, np.float32)
    for t in range(n):
        x = x0 + t
        if x < 0:
            out[t] = row[0]
        elif x >= row.size - 1:
            out[t] = row[row.size - 1]
        else:
            i = int(math.floor(x))
            left, right = np.float64(row[i]), np.float64(row[i + 1])
            out[t] = np.float32((right - left) * (x - i) + left)
    return out


@njit(cache=True)
def _percentile(values, q):
    """The ``q``-th percentile (0-100) of float32 ``values`` (numpy's "linear" method)."""
    s = np.sort(values)
    n = s.size
    v = (n - 1) * (q / 100.0)
    if v >= n - 1:
        return np.float64(s[n - 1])
    i = int(math.floor(v))
    gamma = v - i
    diff = s[i + 1] - s[i]                       # float32
    if gamma >= 0.5:
        return np.float64(s[i + 1]) - np.float64(diff) * (1.0 - gamma)
    return np.float64(s[i]) + np.float64(diff) * gamma


@njit(cache=True)
def _pattern_width(profile, thr, root, window, gap, tolerance):
    """The apparent pattern width sigma (pixels) from the intensity ``profile`` to the
    right of the origin (sample ``t`` at ``t`` pixels), or ``nan``.

    The stripe edges of ``s_p`` lie at ``sigma p^(n/2)``: consecutive edges have the
    ratio ``root`` = ``sqrt(p)``, which survives affine and (nearly) perspective
    distortion. sigma is the largest dark-to-bright edge (crossing of ``thr``) whose three
    preceding edges keep that ratio (within ``tolerance``) and after which the profile
    stays bright for at least ``gap`` (a fraction of sigma; the next edge, the barcode's,
    breaks the ratio: the gap is much narrower than a stripe).
    """
    t32 = np.float32(thr)
    edges = np.empty(profile.size, np.float64)
    rising = np.empty(profile.size, np.bool_)
    m = 0
    for f in range(1, profile.size):
        before, after = profile[f - 1], profile[f]
        if (before > t32) != (after > t32):
            step = after - before if after != before else np.float32(1e-6)
            edges[m] = np.float64(f - 1) + np.float64((t32 - before) / step)
            rising[m] = after > t32
            m += 1
    if m < 4:
        return math.nan
    for j in range(m - 1, 2, -1):
        sigma = edges[j]
        if sigma < window / 2:
            break
        if not rising[j]:
            continue
        keeps = True
        for i in range(j - 3, j):
            if abs(edges[i] / edges[i + 1] - root) > tolerance:
                keeps = False
        if not keeps:
            continue
        if j + 1 < m and edges[j + 1] < sigma * (1 + gap):
            continue
        return sigma
    return math.nan


@njit(cache=True)
def _sum(values):
    """numpy's pairwise sum of float32 ``values`` (8 accumulators, blocks of 128)."""
    n = values.size
    if n < 8:
        res = np.float32(0.0)
        for i in range(n):
            res += values[i]
        return res
    if n <= 128:
        r = values[:8].copy()
        i = 8
        while i < n - n % 8:
            for k in range(8):
                r[k] += values[i + k]
            i += 8
        res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
        for k in range(i, n):
            res += values[k]
        return res
    half = n // 2
    half -= half % 8
    return _sum(values[:half]) + _sum(values[half:])


@njit(cache=True)
def _barcode_bands(gray, x_bar, half, top, bottom, thr):
    """The ``BARCODE_BANDS`` band values (1 = dark) of the barcode column centred on
    column ``x_bar`` (``half`` pixels either side), between the guard bands found within
    half a pattern height of ``top``/``bottom``; empty when there is no such column."""
    none = np.empty(0, np.int64)
    h = bottom - top
    y0 = max(0, int(math.floor(top - 0.5 * h)))
    y1 = min(gray.shape[0], int(math.ceil(bottom + 0.5 * h)))
    if y1 - y0 < BARCODE_BANDS or not (0 <= x_bar - half and x_bar + half < gray.shape[1] - 1):
        return none
    column = np.empty(y1 - y0, np.float32)
    xs = (x_bar - half, x_bar, x_bar + half)
    for y in range(y0, y1):
        acc = np.float32(0.0)
        for k in range(3):
            i = int(math.floor(xs[k]))
            left, right = np.float64(gray[y, i]), np.float64(gray[y, i + 1])
            acc += np.float32((right - left) * (xs[k] - i) + left)
        column[y - y0] = acc / np.float32(3.0)
    t32 = np.float32(thr)
    dark = np.flatnonzero(column < t32)
    if dark.size == 0:
        return none
    start, end = y0 + dark[0] - 0.5, y0 + dark[-1] + 0.5
    band = (end - start) / BARCODE_BANDS
    if band < 1.0 or not (0.5 < (end - start) / h < 2.0):
        return none
    bands = np.empty(BARCODE_BANDS, np.int64)
    for i in range(BARCODE_BANDS):    # each band's mean over its central half
        lo = min(int(np.rint(start + (i + 0.25) * band + 0.5)) - y0, column.size - 1)
        hi = min(max(lo + 1, int(np.rint(start + (i + 0.75) * band + 0.5)) - y0), column.size)
        total = column[lo] + _sum(column[lo + 1:hi])
        bands[i] = total / np.float32(hi - lo) < t32
    return bands


@njit(cache=True)
def _describe_chains(gray, starts, ys, xs, values, row_step, root, gap, half_ratio,
                     bar_ratio, w, xi, ta, wa0, wa1, tb, wb0, wb1):
    """Line, extent, pattern width and barcode of every chain (§3.2); chain ``c`` is
    the matches ``starts[c]:starts[c + 1]`` of ``ys``, ``xs`` (float64) and ``values``.
    Returns ``(n, 8)`` float64 rows ``a, x0, y_mid, top, bottom, sigma, strength,
    has_bands`` and ``(n, BARCODE_BANDS)`` band values.

    The extent: walked along the line from the outermost matches while ``m_y`` stays
    above half the chain's median peak (its ``strength``); each edge lies halfway between
    the last row that passes and the next. The pattern width from the middle row's
    profile right of the line, thresholded halfway between the 5th and 95th percentiles
    of its first ``w`` pixels; the barcode ``bar_ratio * sigma`` right of the line,
    ``half_ratio * sigma`` either side."""
    n = starts.size - 1
    out = np.full((n, 8), np.nan)
    bands = np.zeros((n, BARCODE_BANDS), np.int64)
    for c in range(n):
        cy, cx = ys[starts[c]:starts[c + 1]], xs[starts[c]:starts[c + 1]]
        a, b = _line(cy, cx)
        strength = np.median(values[starts[c]:starts[c + 1]])
        top = _walk(gray, int(cy[0]), -1, 2 * row_step, a, b, 0.5 * strength,
                    w, xi, ta, wa0, wa1, tb, wb0, wb1) - 0.5
        bottom = _walk(gray, int(cy[-1]), 1, 2 * row_step, a, b, 0.5 * strength,
                       w, xi, ta, wa0, wa1, tb, wb0, wb1) + 0.5
        y_mid = int(np.rint((top + bottom) / 2 - 0.5))
        x0 = a * y_mid + b
        profile = _profile(gray[y_mid], x0)
        head = profile[:w]
        lo, hi = _percentile(head, 5.0), _percentile(head, 95.0)
        thr = (lo + hi) / 2
        sigma = _pattern_width(profile, thr, root, w, gap, 0.07)
        out[c] = np.array([a, x0, np.float64(y_mid), top, bottom, sigma, strength, 0.0])
        if math.isfinite(sigma):
            found = _barcode_bands(gray, x0 + bar_ratio * sigma, half_ratio * sigma, top,
                                   bottom, thr)
            if found.size:
                bands[c] = found
                out[c, 7] = 1.0
    return out, bands


def _chain_arrays(chains: list[list[_Match]]) -> tuple[np.ndarray, ...]:
    """The chains as flat arrays for :func:`_describe_chains`: start offsets, rows,
    columns, peak values."""
    matches = [m for chain in chains for m in chain]
    starts = np.cumsum([0] + [len(chain) for chain in chains])
    return (starts, np.array([m.y for m in matches], np.float64),
            np.array([m.x for m in matches], np.float64),
            np.array([m.value for m in matches], np.float64))


def detect_landmarks(image: np.ndarray, model: CameraModel,
                     config: DetectorConfig = DetectorConfig()) -> list[Detection]:
    """Every self-similar landmark in ``image`` (uint8 RGB/grey, or float grey in [0, 1])
    seen through ``model``, strongest first; at most one detection per id."""
    gray = np.ascontiguousarray(to_gray(image) if np.asarray(image).dtype == np.uint8
                                else np.asarray(image, dtype=np.float32))
    width = gray.shape[1]
    if model.wraps:  # a panorama: continue each row past its end so patterns may wrap
        gray = np.concatenate([gray, gray[:, :width // 2]], axis=1)
    cfg, lay = config, config.layout
    chains = _chains(_scan(gray, cfg, width), cfg)
    if not chains:
        return []
    rows, bands = _describe_chains(
        gray, *_chain_arrays(chains), cfg.row_step, math.sqrt(cfg.p),
        0.5 * lay.gap / lay.pattern_width, 0.25 * lay.barcode_width / lay.pattern_width,
        lay.barcode_centre, cfg.window, *_taps(cfg.p, cfg.window))
    span = (lay.pattern_width + lay.gap + lay.barcode_width) / lay.pattern_width
    found: list[Detection] = []
    for chain, (a, x0, y_mid, top, bottom, sigma, strength, has_bands), code in zip(
            chains, rows.tolist(), bands.tolist()):
        landmark_id = decode_barcode(code) if has_bands else None
        if cfg.require_id and landmark_id is None:
            continue
        centre = x0 + 0.5 * span * sigma if math.isfinite(sigma) else x0
        found.append(Detection(
            id=landmark_id, x=float(x0 % width if model.wraps else x0), y=y_mid,
            top=top, bottom=bottom, slope=a, width=sigma,
            centre_x=float(centre % width if model.wraps else centre),
            bearing=wrap_angle(float(model.bearing(centre))),
            distance=model.distance(x0, top, bottom, lay.pattern_height),
            strength=strength, matches=len(chain)))
    found.sort(key=lambda d: -d.strength * d.matches)
    unique: list[Detection] = []
    for det in found:
        if det.id is None or all(u.id != det.id for u in unique):
            unique.append(det)
    return unique
