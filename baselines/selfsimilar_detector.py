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
import statistics
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from numba import njit

from homing_baselines.camera_models import CameraModel
from homing_gym.geometry import wrap_angle
from homing_gym.vision import luminance
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
    """Luminance in ``[0, 1]`` (float32) of a uint8 RGB or grey image."""
    return luminance(image)


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


def _interp(gray: np.ndarray, y: int, xs: np.ndarray) -> np.ndarray:
    """Row ``y`` of ``gray`` at fractional columns ``xs`` (linear, ``np.interp``; the end
    values beyond the image)."""
    return np.interp(xs, np.arange(gray.shape[1]), gray[y]).astype(np.float32)


def _columns(gray: np.ndarray, xs: np.ndarray, y0: int, y1: int) -> np.ndarray:
    """Rows ``y0 .. y1-1`` of ``gray`` at fractional columns ``xs`` inside the image,
    ``(y1 - y0, len(xs))`` float32: :func:`_interp` of every row at once (the same
    float64 arithmetic as ``np.interp``: ``(right - left) * t + left``)."""
    i = np.floor(xs).astype(np.int64)
    left = gray[y0:y1, i].astype(np.float64)
    right = gray[y0:y1, i + 1].astype(np.float64)
    return ((right - left) * (xs - i) + left).astype(np.float32)


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


def _extent(gray: np.ndarray, chain: list[_Match], a: float, b: float, strength: float,
            cfg: DetectorConfig) -> tuple[float, float]:
    """Rows of the pattern's top and bottom edges along the line ``x = a y + b``: walked
    from the outermost matches while ``m_y`` stays above half the chain's median peak
    ``strength``; each edge lies halfway between the last row that passes and the next."""
    taps = _taps(cfg.p, cfg.window)
    edges = []
    for start, direction in ((chain[0].y, -1), (chain[-1].y, 1)):
        y = _walk(gray, start, direction, 2 * cfg.row_step, float(a), float(b),
                  0.5 * strength, cfg.window, *taps)
        edges.append(y + 0.5 * direction)
    return edges[0], edges[1]


def _pattern_width(profile: np.ndarray, lo: float, hi: float, cfg: DetectorConfig,
                   tolerance: float = 0.07) -> float:
    """The apparent pattern width sigma (pixels) from the intensity ``profile`` to the
    right of the origin (sample ``t`` at ``t`` pixels), or ``nan``.

    The stripe edges of ``s_p`` lie at ``sigma p^(n/2)``: consecutive edges have the
    ratio ``sqrt(p)``, which survives affine and (nearly) perspective distortion. sigma
    is the largest dark-to-bright edge whose three preceding edges keep that ratio (within
    ``tolerance``) and after which the profile stays bright for at least half the gap
    (the next edge of the barcode breaks the ratio: the gap is much narrower than a
    stripe).
    """
    thr = (lo + hi) / 2
    bright = profile > thr
    flips = np.flatnonzero(bright[:-1] != bright[1:]) + 1
    if flips.size < 4:
        return math.nan
    # sub-pixel edge positions by linear interpolation between samples f - 1 and f
    before, after = profile[flips - 1], profile[flips]
    edges = flips - 1 + (thr - before) / np.where(after != before, after - before, 1e-6)
    rising = bright[flips]
    root = math.sqrt(cfg.p)
    gap = 0.5 * cfg.layout.gap / cfg.layout.pattern_width
    for j in range(edges.size - 1, 2, -1):
        sigma = float(edges[j])
        if sigma < cfg.window / 2:
            break
        if not rising[j]:
            continue
        ratios = edges[j - 3:j] / edges[j - 2:j + 1]
        if np.any(np.abs(ratios - root) > tolerance):
            continue
        if j + 1 < edges.size and edges[j + 1] < sigma * (1 + gap):
            continue
        return sigma
    return math.nan


def _barcode(gray: np.ndarray, x_bar: float, half: float, top: float, bottom: float,
             thr: float) -> int | None:
    """Read the barcode column centred on column ``x_bar`` (``half`` pixels either side)
    between the guard bands found within half a pattern height of ``top``/``bottom``."""
    h = bottom - top
    y0, y1 = max(0, int(math.floor(top - 0.5 * h))), min(gray.shape[0], int(math.ceil(bottom + 0.5 * h)))
    if y1 - y0 < BARCODE_BANDS or not (0 <= x_bar - half and x_bar + half < gray.shape[1] - 1):
        return None
    xs = x_bar + np.array([-half, 0.0, half])
    column = _columns(gray, xs, y0, y1).mean(axis=1)
    dark = np.flatnonzero(column < thr)
    if dark.size == 0:
        return None
    start, end = y0 + int(dark[0]) - 0.5, y0 + int(dark[-1]) + 0.5
    band = (end - start) / BARCODE_BANDS
    if band < 1.0 or not (0.5 < (end - start) / h < 2.0):
        return None
    # each band's mean over its central half: rows [lo, hi) (sums by np.add.reduceat over
    # the bounds lo_0, hi_0, lo_1, ...; every other sum is a band's)
    bounds = []
    for i in range(BARCODE_BANDS):
        lo = int(round(start + (i + 0.25) * band + 0.5))
        bounds += [lo - y0, max(lo + 1, int(round(start + (i + 0.75) * band + 0.5))) - y0]
    bounds = np.array(bounds)
    sums = np.add.reduceat(np.append(column, np.float32(0)), bounds)[::2]
    means = sums / (bounds[1::2] - bounds[::2]).astype(np.float32)
    return decode_barcode([int(m < thr) for m in means])


def detect_landmarks(image: np.ndarray, model: CameraModel,
                     config: DetectorConfig = DetectorConfig()) -> list[Detection]:
    """Every self-similar landmark in ``image`` (uint8 RGB/grey, or float grey in [0, 1])
    seen through ``model``, strongest first; at most one detection per id."""
    gray = np.ascontiguousarray(to_gray(image) if np.asarray(image).dtype == np.uint8
                                else np.asarray(image, dtype=np.float32))
    width = gray.shape[1]
    if model.wraps:  # a panorama: continue each row past its end so patterns may wrap
        gray = np.concatenate([gray, gray[:, :width // 2]], axis=1)
    cfg = config
    found: list[Detection] = []
    for chain in _chains(_scan(gray, cfg, width), cfg):
        ys = np.array([m.y for m in chain], dtype=np.float64)
        xs = np.array([m.x for m in chain], dtype=np.float64)
        a, b = np.polyfit(ys, xs, 1)
        strength = statistics.median([m.value for m in chain])
        top, bottom = _extent(gray, chain, a, b, strength, cfg)
        y_mid = int(round((top + bottom) / 2 - 0.5))
        x0 = a * y_mid + b
        profile = _interp(gray, y_mid, x0 + np.arange(0, gray.shape[1] - x0 - 1))
        head = profile[:cfg.window]
        lo, hi = (float(v) for v in np.percentile(head, [5, 95]))
        sigma = _pattern_width(profile, lo, hi, cfg)
        lay = cfg.layout
        landmark_id = None
        if math.isfinite(sigma):
            half = 0.25 * lay.barcode_width / lay.pattern_width * sigma
            landmark_id = _barcode(gray, x0 + lay.barcode_centre * sigma, half, top, bottom,
                                   (lo + hi) / 2)
        if cfg.require_id and landmark_id is None:
            continue
        span = (lay.pattern_width + lay.gap + lay.barcode_width) / lay.pattern_width
        centre = x0 + 0.5 * span * sigma if math.isfinite(sigma) else x0
        found.append(Detection(
            id=landmark_id, x=float(x0 % width if model.wraps else x0), y=y_mid + 0.0,
            top=float(top), bottom=float(bottom), slope=float(a), width=sigma,
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
