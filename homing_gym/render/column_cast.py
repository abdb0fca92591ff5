"""Exact ray casting for cameras whose pixel columns are vertical half-planes (numba).

Every camera of the package is upright: the rays of one image column all lie in one
vertical half-plane through the camera (the cylindrical panorama's columns, and those of
an upright pinhole view). A column is then described by its bearing ``beta`` (radians,
counter-clockwise from the heading) and each of its rows by the tangent of the ray's
elevation. :func:`cast_columns` intersects every triangle with the half-planes of the
columns it can reach (the bearing span of its corners), which leaves a segment in that
plane, and intersects the segment with the rows' rays in closed form; the nearest hit per
pixel wins (depth = horizontal distance, monotone along each ray). So every pixel's
result is the exact intersection of its own ray with the mesh, the same as a general ray
caster's (Embree: tested), at the cost of a rasteriser: triangles x the columns they
span, plus the pixels they cover. Of two hits at the same distance (on an edge shared by
two triangles) the lower triangle index wins.

Most of a detailed world's triangles are small (a column or two wide, often between two
rows), so the work per triangle and per triangle-column pair is what counts. It is done
in passes that the compiler vectorises (no branch, arrays read at fixed strides): every
triangle's facing and bearing span at once, with a polynomial arctangent and a slightly
widened interval (:func:`triangle_spans`); the pairs cut :data:`CHUNK` at a time, with the
segments that fall between two rows dropped (:func:`_cut_columns`); then the rows of
each pair, in the triangles' order (:func:`_fill_rows`). Every shortcut only widens what
is tested exactly, so the pixels are those of the plain search (tested).

In a world dense with small triangles (:data:`CULL_DENSITY`: grass, clutter) most of them
are hidden behind nearer ones. There the triangles are grouped in cells of the ground
(:func:`triangle_grid`) and a panorama casts them front to back, skipping those that
stand wholly below the rows already covered by something nearer in every column they
span (:func:`_uncovered`): what it casts tracks what is visible more than what is there.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from homing_gym.render.shadows import in_shadow

#: Hits nearer than this (metres, horizontally) are ignored: the camera's own position.
NEAR = 1e-6


@njit(cache=True, error_model="numpy", inline="always")
def _past(v: float, value: float, strict: bool) -> bool:
    return v < value if strict else v <= value


@njit(cache=True, error_model="numpy", nogil=True)
def _first_past(values: np.ndarray, value: float, strict: bool, guess: int) -> int:
    """First index ``i`` at which the descending ``values`` fall below ``value``
    (``values[i] < value``, or ``<=`` when not ``strict``), or ``len(values)``.

    Searched outward from ``guess`` in doubling steps, then by bisection, so a guess a
    few places off costs a few steps; a negative ``guess``: plain bisection."""
    n = values.shape[0]
    lo, hi = 0, n
    if guess >= 0:
        g = min(guess, n)
        if g == n or _past(values[g], value, strict):      # the answer is at most g
            hi, step, lo = g, 1, g - 1
            while lo >= 0 and _past(values[lo], value, strict):
                hi = lo
                step *= 2
                lo = hi - step
            lo = max(lo + 1, 0)
        else:                                              # the answer is past g
            lo, step = g + 1, 1
            hi = lo
            while hi < n and not _past(values[hi], value, strict):
                lo = hi + 1
                step *= 2
                hi = min(lo + step - 1, n)
    while lo < hi:
        mid = (lo + hi) // 2
        if _past(values[mid], value, strict):
            hi = mid
        else:
            lo = mid + 1
    return lo


@njit(cache=True, error_model="numpy", inline="always")
def _edge_cut(c: float, s: float, dk: float, dm: float, xk: float, yk: float, zk: float,
              xm: float, ym: float, zm: float):
    """Where the edge from corner ``k`` to corner ``m`` (relative to the camera; ``dk``,
    ``dm`` their signed distances from the plane) crosses the vertical plane of
    horizontal direction ``(c, s)``: ``(u, along, height)``, ``u`` the fraction of the
    way from ``k``."""
    u = dk / (dk - dm)
    return u, (1 - u) * (c * xk + s * yk) + u * (c * xm + s * ym), (1 - u) * zk + u * zm


@njit(cache=True, error_model="numpy", inline="always")
def _column_segment(x0: float, y0: float, z0: float, x1: float, y1: float, z1: float,
                    x2: float, y2: float, z2: float, c: float, s: float):
    """The triangle with corners ``(x0, y0, z0)``, ... (relative to the camera) cut by
    the vertical plane of horizontal direction ``(c, s)``, clipped to the half-plane in
    front: ``(ok, a0, h0, a1, h1, w0, w1)``, its two ends' distance along the plane
    and height (metres) and barycentric weights (tuples of 3); ``ok`` False when the
    triangle misses the half-plane. The ends follow the triangle's edges in order (0-1,
    1-2, 2-0): the corner alone on its side of the plane is the one both cut edges
    share. All three edges are cut and the two crossing ones picked, with no branch,
    so that a loop over many is vectorised."""
    d0, d1, d2 = -s * x0 + c * y0, -s * x1 + c * y1, -s * x2 + c * y2
    b0, b1, b2 = d0 >= 0.0, d1 >= 0.0, d2 >= 0.0
    alone2 = b0 == b1                                  # edges 1-2, 2-0
    alone1 = (b0 == b2) & ~alone2                      # edges 0-1, 1-2
    u01, a01, h01 = _edge_cut(c, s, d0, d1, x0, y0, z0, x1, y1, z1)
    u12, a12, h12 = _edge_cut(c, s, d1, d2, x1, y1, z1, x2, y2, z2)
    u20, a20, h20 = _edge_cut(c, s, d2, d0, x2, y2, z2, x0, y0, z0)
    a0 = a12 if alone2 else a01
    h0 = h12 if alone2 else h01
    w00 = 0.0 if alone2 else 1 - u01
    w01 = 1 - u12 if alone2 else u01
    w02 = u12 if alone2 else 0.0
    a1 = a12 if alone1 else a20
    h1 = h12 if alone1 else h20
    w10 = 0.0 if alone1 else u20
    w11 = 1 - u12 if alone1 else 0.0
    w12 = u12 if alone1 else 1 - u20
    ok = ~((b0 == b1) & (b1 == b2)) & ((a0 >= NEAR) | (a1 >= NEAR))
    a0, h0, w0 = _in_front(a0, h0, (w00, w01, w02), a1, h1, (w10, w11, w12))
    a1, h1, w1 = _in_front(a1, h1, (w10, w11, w12), a0, h0, w0)
    return ok, a0, h0, a1, h1, w0, w1


@njit(cache=True, error_model="numpy", inline="always")
def _in_front(a: float, h: float, w: tuple, a_other: float, h_other: float, w_other: tuple):
    """A segment's end ``(a, h, w)`` (distance along, height, weights), if it lies behind
    the camera (``a < NEAR``), moved along the segment towards the other end to just in
    front of it; no branch."""
    f = (NEAR - a) / (a_other - a)
    behind = a < NEAR
    return ((a + f * (a_other - a) if behind else a), (h + f * (h_other - h) if behind else h),
            (w[0] + f * (w_other[0] - w[0]) if behind else w[0],
             w[1] + f * (w_other[1] - w[1]) if behind else w[1],
             w[2] + f * (w_other[2] - w[2]) if behind else w[2]))


#: ``atan(a) = a * P(a**2)`` on ``[0, 1]``: a least-squares Chebyshev fit of degree 7
#: in ``a**2``, within 2.9e-7 rad of the arctangent (tested).
_ATAN_COEFFICIENTS = (0.9999999227737695, -0.3333223260372159, 0.19974028405362163,
                      -0.14047820368966144, 0.10002203051723593, -0.060874452164450414,
                      0.025331680256184555, -0.005021058164641616)
#: How far (radians) :func:`triangle_spans` widens each interval beyond its approximate
#: angles: more than the error of two approximate arctangents.
_ATAN_SLACK = 1e-6
#: How far (columns) an interval's columns are widened where they are found by
#: arithmetic on evenly spaced bearings, beyond the rounding of that arithmetic.
_INDEX_SLACK = 1e-6
#: :func:`triangle_spans`' kinds of triangle.
SKIP, SPAN, EVERYWHERE = 0, 1, 2


@njit(cache=True, error_model="numpy", inline="always")
def _approx_atan2(y: float, x: float) -> float:
    """``atan2(y, x)`` to within 2.9e-7 rad (radians, in ``[-pi, pi]``), with one
    division and a polynomial instead of the library's arctangent, and no branch (so
    that a loop over many can be vectorised)."""
    ax, ay = abs(x), abs(y)
    big, small = max(ax, ay), min(ax, ay)
    a = small / (big if big > 0.0 else 1.0)
    z = a * a
    c = _ATAN_COEFFICIENTS
    r = a * (c[0] + z * (c[1] + z * (c[2] + z * (c[3] + z * (c[4] + z * (c[5] + z * (c[6]
                                                                                 + z * c[7])))))))
    r = 0.5 * math.pi - r if ay > ax else r
    r = math.pi - r if x < 0.0 else r
    return -r if y < 0.0 else r


@njit(cache=True, error_model="numpy", inline="always")
def _bearing_span(corners: np.ndarray, normals: np.ndarray, closed: np.ndarray, t: int,
                  ox: float, oy: float, oz: float, yaw: float):
    """``(lo, hi, kind)`` of triangle ``t`` seen from ``(ox, oy, oz)`` (see
    :func:`triangle_spans`); no branch."""
    x0, y0 = corners[0, t] - ox, corners[1, t] - oy
    x1, y1 = corners[3, t] - ox, corners[4, t] - oy
    x2, y2 = corners[6, t] - ox, corners[7, t] - oy
    facing = (normals[0, t] * x0 + normals[1, t] * y0 + normals[2, t] * (corners[2, t] - oz))
    away = closed[t] & (facing >= 0.0)
    c0, c1, c2 = x0 * y1 - y0 * x1, x1 * y2 - y1 * x2, x2 * y0 - y2 * x0
    edge_on = (c0 == 0.0) & (c1 == 0.0) & (c2 == 0.0)
    around = (((c0 >= 0.0) & (c1 >= 0.0) & (c2 >= 0.0))
              | ((c0 <= 0.0) & (c1 <= 0.0) & (c2 <= 0.0)))
    d1 = _approx_atan2(x0 * y1 - y0 * x1, x0 * x1 + y0 * y1)
    d2 = _approx_atan2(x0 * y2 - y0 * x2, x0 * x2 + y0 * y2)
    a0 = _approx_atan2(y0, x0) - yaw
    a0 -= 2 * math.pi * np.floor((a0 + math.pi) * (0.5 / math.pi))   # into about [-pi, pi)
    return (a0 + min(min(d1, d2), 0.0) - _ATAN_SLACK, a0 + max(max(d1, d2), 0.0) + _ATAN_SLACK,
            (SPAN + around) * (1 - (away | edge_on)))


@njit(cache=True, error_model="numpy", nogil=True)
def triangle_spans(corners: np.ndarray, normals: np.ndarray, closed: np.ndarray,
                   origin: np.ndarray, yaw: float, k0: int, k1: int, lo: np.ndarray,
                   hi: np.ndarray, kind: np.ndarray) -> None:
    """Which triangles the camera can see, and over which bearings.

    ``corners (9, N)``: the triangles' corners coordinate by coordinate (``x0, y0, z0,
    x1, ...``, metres), ``normals (3, N)``, ``closed (N,)`` as in :func:`cast_columns`.
    Writes ``kind[t]``: :data:`SKIP` (a closed solid's face turned away from the camera,
    or one seen edge-on), :data:`EVERYWHERE` (the camera's vertical line passes through
    it) or :data:`SPAN`, with ``[lo[t], hi[t]]`` holding the bearings of its corners
    relative to the heading (radians, counter-clockwise; ``hi - lo < pi``; both within
    ``[-2 pi, 2 pi]`` for any heading, the first corner's bearing being wrapped into
    ``[-pi, pi)``), widened by
    :data:`_ATAN_SLACK` beyond the error of the approximate arctangents, so that no
    column the triangle reaches is missed: the caster tests each column exactly.
    Only the triangles ``k0 <= t < k1``. Branch-free per triangle, so that the loop is
    vectorised."""
    for t in range(k0, k1):
        lo[t], hi[t], kind[t] = _bearing_span(corners, normals, closed, t, origin[0],
                                              origin[1], origin[2], yaw)


@njit(cache=True, error_model="numpy", inline="always")
def _columns(beta: np.ndarray, lo: float, hi: float, per_radian: float):
    """``(j0, j1)``: the columns ``j0 <= j < j1`` whose bearing lies in ``[lo, hi]``
    (a little wider), empty when none does."""
    W = beta.shape[0]
    if hi + 1e-12 <= beta[W - 1] or lo - 1e-12 > beta[0]:
        return 0, 0
    j0 = _first_past(beta, hi + 1e-12, True, int(max((beta[0] - hi) * per_radian, 0.0)))
    j1 = _first_past(beta, lo - 1e-12, True, int(max((beta[0] - lo) * per_radian, 0.0)))
    return j0, j1


#: Triangle-column pairs cut at once by :func:`_cut_columns` (its buffers stay in the
#: first-level cache).
CHUNK = 256
#: Rows of the pairs :func:`_cut_columns` reads after the 9 corners (relative to the
#: camera): the column's horizontal direction, its first row's elevation (radians) and
#: rows per radian if they were evenly spaced.
_COS, _SIN, _TOP_ANGLE, _ROWS_PER_RADIAN = 9, 10, 11, 12
#: How far (rows) :func:`_cut_columns` widens a segment's fractional rows before it
#: decides the segment falls between two: far beyond the error of its approximate
#: arctangents (under 1e-4 rows at 0.01 rad a row).
_ROW_SLACK = 1e-3
#: Rows of :func:`_cut_columns`' output.
(_OK, _A0, _H0, _A1, _H1, _W00, _W01, _W02, _W10, _W11, _W12, _TOP, _LOW, _GUESS,
 _END_GUESS) = range(15)


@njit(cache=True, error_model="numpy", nogil=True)
def _cut_columns(n: int, p: np.ndarray, H: int, even_rows: bool, top_angle: float,
                 rows_per_radian: float, out: np.ndarray) -> None:
    """For the first ``n`` pairs ``p[:, k]`` (:func:`cast_columns`): the triangle cut
    by the plane of the column (:func:`_column_segment`), the tangents of the
    elevations of the segment's ends (``_TOP``, ``_LOW``), and a guess of the first row
    at or below the upper one, as if rows were evenly spaced in elevation (with
    ``even_rows`` they are, from ``top_angle`` at ``rows_per_radian`` in every column;
    else each pair holds its column's). With ``even_rows`` a segment that falls between two rows is dropped (``_OK``
    0): a quarter to a third of them in a world of small triangles. Branch-free, and
    with the rows of ``p`` and ``out`` at constant distances in flat arrays (so that
    the compiler sees they cannot overlap): vectorised."""
    C = CHUNK
    for k in range(n):
        ok, a0, h0, a1, h1, w0, w1 = _column_segment(
            p[k], p[C + k], p[2 * C + k], p[3 * C + k], p[4 * C + k], p[5 * C + k],
            p[6 * C + k], p[7 * C + k], p[8 * C + k], p[_COS * C + k], p[_SIN * C + k])
        ta, tb = h0 / a0, h1 / a1
        top = max(ta, tb)
        low = min(ta, tb)
        # fractional rows of the ends: the rows covered are the whole numbers between
        first = top_angle if even_rows else p[_TOP_ANGLE * C + k]
        per = rows_per_radian if even_rows else p[_ROWS_PER_RADIAN * C + k]
        upper = (first - _approx_atan2(top, 1.0)) * per
        lower = (first - _approx_atan2(low, 1.0)) * per
        between = even_rows & (math.ceil(upper - _ROW_SLACK) > math.floor(lower + _ROW_SLACK))
        out[_OK * C + k] = (1.0 if ok else 0.0) * (0.0 if between else 1.0)
        out[_A0 * C + k], out[_H0 * C + k], out[_A1 * C + k], out[_H1 * C + k] = a0, h0, a1, h1
        out[_W00 * C + k], out[_W01 * C + k], out[_W02 * C + k] = w0
        out[_W10 * C + k], out[_W11 * C + k], out[_W12 * C + k] = w1
        out[_TOP * C + k], out[_LOW * C + k] = top, low
        out[_GUESS * C + k] = min(max(math.ceil(upper), 0.0), float(H))
        out[_END_GUESS * C + k] = min(max(math.floor(lower) + 1.0, 0.0), float(H))


@njit(cache=True, error_model="numpy", inline="always")
def _row_hit(ti: float, a0: float, h0: float, a1: float, h1: float, da: float, depth: float):
    """``(nearer, as_near, u, dist)``: where the ray of elevation tangent ``ti`` meets
    the segment from ``(a0, h0)`` to ``(a1, h1)`` (``u`` the fraction of the way), and
    whether that is nearer than ``depth``, or as near; no branch."""
    fa = h0 - ti * a0
    fb = h1 - ti * a1
    u = min(max(fa / (fa - fb), 0.0), 1.0)
    dist = a0 + u * da
    return (dist < depth) & (fa != fb), (dist == depth) & (fa != fb), u, dist


def _rows_kernel(ties: bool):
    """:func:`_rows` with or without ``ties`` (of two hits at the same distance the lower
    triangle index wins, else the first), compiled apart so that neither pays for the
    other's test."""

    @njit(cache=True, error_model="numpy", nogil=True)
    def rows(first: int, end: int, t: int, j: int, jr: int, tan_elev: np.ndarray, a0: float,
             h0: float, a1: float, h1: float, da: float, hit: np.ndarray,
             depth: np.ndarray) -> bool:
        """Rows ``first <= i < end`` of column ``j`` (tangents from column ``jr``) where
        triangle ``t``'s segment beats the hit so far take it; whether any did. No
        branch, and unsigned indices (numba reads them without testing for negative
        ones): vectorised."""
        wins = 0
        ju, jru = np.uint64(j), np.uint64(jr)
        for q in range(end - first):
            i = np.uint64(first + q)
            closer, as_near, _, dist = _row_hit(tan_elev[i, jru], a0, h0, a1, h1, da,
                                                depth[ju, i])
            if ties:              # a constant: numba drops the branch not taken
                closer |= as_near & (t < hit[i, ju])
            depth[ju, i] = dist if closer else depth[ju, i]
            hit[i, ju] = t if closer else hit[i, ju]
            wins += closer
        return wins > 0

    return rows


_rows, _rows_by_index = _rows_kernel(False), _rows_kernel(True)


@njit(cache=True, error_model="numpy", nogil=True)
def _rows_weighted(first: int, end: int, t: int, j: int, jr: int, tan_elev: np.ndarray,
                   a0: float, h0: float, a1: float, h1: float, da: float, w0: float, w1: float,
                   w2: float, dw0: float, dw1: float, dw2: float, hit: np.ndarray,
                   weights: np.ndarray, depth: np.ndarray, ties: bool) -> bool:
    """:func:`_rows`, also writing the barycentric weights of the hits."""
    wins = False
    for i in range(first, end):
        nearer, as_near, u, dist = _row_hit(tan_elev[i, jr], a0, h0, a1, h1, da, depth[j, i])
        if nearer or (ties and as_near and t < hit[i, j]):
            wins = True
            depth[j, i] = dist
            hit[i, j] = t
            weights[i, j, 0] = w0 + u * dw0
            weights[i, j, 1] = w1 + u * dw1
            weights[i, j, 2] = w2 + u * dw2
    return wins


@njit(cache=True, error_model="numpy", nogil=True)
def _fill_rows(n: int, triangle: np.ndarray, column: np.ndarray, level: np.ndarray,
               cut: np.ndarray, tan_elev: np.ndarray, even_rows: bool, weighted: np.ndarray,
               hit: np.ndarray, weights: np.ndarray, depth: np.ndarray, bound: np.ndarray,
               ties: bool, listed: np.ndarray, drawn: np.ndarray, m: int) -> int:
    """The rows of the first ``n`` cut pairs (:func:`_cut_columns`): each ray of the
    column between the segment's ends hits it at a distance found in closed form; the
    nearest hit so far per pixel wins. With ``even_rows`` every column's rows are read
    from the first column, so that the image's memory stays in the cache. A pair of
    ``level[k] >= 0`` lies beyond ``reach[level[k]]``: its rows from ``bound[level[k],
    j]`` down are already covered by something nearer (:func:`_uncovered`), and
    skipped. ``ties``: of two hits at the same distance the lower triangle index wins
    (else the first cast). Appends to ``drawn[:m]`` the triangles not yet ``listed``
    that win a pixel; returns the new ``m``."""
    H, C = tan_elev.shape[0], CHUNK
    for k in range(n):
        if cut[_OK * C + k] == 0.0:
            continue
        t, j = triangle[k], column[k]
        jr = 0 if even_rows else j          # the column whose rows are read
        with_weights = weighted[t]
        a0, h0, a1, h1 = cut[_A0 * C + k], cut[_H0 * C + k], cut[_A1 * C + k], cut[_H1 * C + k]
        w0, w1, w2 = cut[_W00 * C + k], cut[_W01 * C + k], cut[_W02 * C + k]
        da = a1 - a0
        dw0, dw1, dw2 = cut[_W10 * C + k] - w0, cut[_W11 * C + k] - w1, cut[_W12 * C + k] - w2
        lowest = cut[_LOW * C + k]
        # the first row at or below the segment's top and the first below its bottom:
        # walked to from their guesses
        top, first = cut[_TOP * C + k], int(cut[_GUESS * C + k])
        while first > 0 and tan_elev[first - 1, jr] <= top:
            first -= 1
        while first < H and tan_elev[first, jr] > top:
            first += 1
        end = max(int(cut[_END_GUESS * C + k]), first)
        while end > first and tan_elev[end - 1, jr] < lowest:
            end -= 1
        while end < H and tan_elev[end, jr] >= lowest:
            end += 1
        if level[k] >= 0:
            end = min(end, bound[level[k], j])
        if with_weights:
            wins = _rows_weighted(first, end, t, j, jr, tan_elev, a0, h0, a1, h1, da, w0, w1,
                                  w2, dw0, dw1, dw2, hit, weights, depth, ties)
        else:
            wins = (_rows_by_index(first, end, t, j, jr, tan_elev, a0, h0, a1, h1, da, hit,
                                   depth) if ties else
                    _rows(first, end, t, j, jr, tan_elev, a0, h0, a1, h1, da, hit, depth))
        if wins and not listed[t]:
            listed[t] = True
            drawn[m] = t
            m += 1
    return m


class Triangles(NamedTuple):
    """The world's triangles as :func:`cast_columns` reads them (:func:`triangle_grid`):
    ``corners (9, N)`` coordinate by coordinate (``x0, y0, z0, x1, ...``, metres),
    ``normals (3, N)``, ``closed (N,)`` (a closed solid's face, its normal pointing
    out), ``index (N,)`` each one's index in the world mesh (what the caster writes),
    ``top (N,)`` its highest corner's height; ``reach (L,)`` the distances (metres) of
    the occlusion levels (:func:`_uncovered`). For occlusion culling the triangles are
    grouped by cell: ``start[0]:start[1]`` those that reach across more than a cell,
    cell ``c``'s ``start[c + 1]:start[c + 2]`` (in the order of their tops), ``box (C,
    4)`` the ``(xmin, ymin, xmax, ymax)`` of each cell's triangles; else they are in the
    mesh's order, ``start = [0, N]`` and there are no cells."""

    corners: np.ndarray
    normals: np.ndarray
    closed: np.ndarray
    index: np.ndarray
    top: np.ndarray
    start: np.ndarray
    box: np.ndarray
    reach: np.ndarray


#: Side (metres) of :func:`triangle_grid`'s cells, and the most cells along a side (a
#: larger world gets larger cells).
CELL, MAX_CELLS = 1.0, 64
#: Triangles no wider than a cell per square metre (of the rectangle they span) from
#: which the caster culls hidden ones: its tests skip more than half the
#: triangle-column pairs of ``grass50k`` (500 per square metre), under a quarter in the
#: 10,000-triangle worlds (about 100), where they cost more than they save.
CULL_DENSITY = 250.0
#: Cells nearer than this (metres) are not tested for occlusion; beyond it, the distances
#: of the occlusion levels (:attr:`Triangles.reach`) grow by this factor per level.
NEAR_CELLS, LEVEL_FACTOR = 1.0, 2 ** 0.25
#: Relative margin by which an occlusion test widens heights and distances: far beyond
#: the rounding of the caster's arithmetic (about 1e-15).
_OCCLUSION_SLACK = 1e-9


def triangle_grid(triangles: np.ndarray, normals: np.ndarray, closed: np.ndarray,
                  cell: float = CELL, cull_density: float = CULL_DENSITY) -> Triangles:
    """The :class:`Triangles` of a mesh's ``triangles (N, 3, 3)`` (float32 corners),
    ``normals (N, 3)`` and ``closed (N,)``: each triangle no wider than a cell (``cell``
    metres, or more in a world over :data:`MAX_CELLS` cells across) in the square cell
    of its centre, the others first, where such triangles are at least
    ``cull_density`` per square metre of the rectangle they span; else no cells."""
    tris = np.asarray(triangles, np.float32)
    low, high = tris[:, :, :2].min(1).astype(np.float64), tris[:, :, :2].max(1).astype(np.float64)
    corner, size = low.min(0), high.max(0) - low.min(0)
    side = max(cell, float(size.max()) / MAX_CELLS)
    cells = np.maximum(np.ceil(size / side), 1).astype(np.int64)
    large = (high - low).max(1) > side
    ij = np.minimum(((low + high) / 2 - corner) // side, cells - 1).astype(np.int64)
    key = np.where(large, -1, ij[:, 0] * cells[1] + ij[:, 1])
    top = tris[:, :, 2].max(1).astype(np.float64)
    order = np.arange(len(tris))
    start, box = np.array([0, len(tris)], np.int64), np.zeros((0, 4))
    spread = (high[~large].max(0) - low[~large].min(0)) if (~large).any() else np.zeros(2)
    if (~large).sum() >= cull_density * max(float(spread[0] * spread[1]), side * side):
        order = np.lexsort((top, key))              # the large ones (key -1) first
        small = order[~large[order]]
        first = np.flatnonzero(np.r_[True, key[small][1:] != key[small][:-1]])
        start = np.r_[0, len(tris) - len(small) + first, len(tris)].astype(np.int64)
        box = np.column_stack([np.minimum.reduceat(low[small], first),
                               np.maximum.reduceat(high[small], first)])
    levels = 1 + max(0, math.ceil(math.log(max(float(np.hypot(*size)) + 2 * side, NEAR_CELLS)
                                           / NEAR_CELLS, LEVEL_FACTOR)))
    return Triangles(np.ascontiguousarray(tris[order].reshape(-1, 9).T),
                     np.ascontiguousarray(np.asarray(normals, np.float32)[order].T),
                     np.asarray(closed, np.bool_)[order], order.astype(np.int64), top[order],
                     start, box, NEAR_CELLS * LEVEL_FACTOR ** np.arange(levels))


@njit(cache=True, error_model="numpy", nogil=True)
def cast_columns(corners: np.ndarray, normals: np.ndarray, closed: np.ndarray,
                 index: np.ndarray, top: np.ndarray, start: np.ndarray, box: np.ndarray,
                 reach: np.ndarray, origin: np.ndarray, yaw: float, beta: np.ndarray,
                 tan_elev: np.ndarray, circle: bool, even_rows: bool, top_angle: np.ndarray,
                 rows_per_radian: np.ndarray, weighted: np.ndarray, hit: np.ndarray,
                 weights: np.ndarray, depth: np.ndarray, drawn: np.ndarray) -> int:
    """Nearest triangle per pixel.

    ``corners`` to ``reach``: the world's triangles (the fields of :class:`Triangles`,
    passed one by one: numba reads a tuple's type slowly); a closed solid's face is skipped
    when turned away from the camera (hidden by the solid's near side whenever the
    camera is outside the solid); ``origin (3,)`` the camera; ``yaw`` its heading
    (radians); ``beta (W,)`` column bearings relative to the heading, strictly
    descending within ``(-pi, pi]``; ``tan_elev (H, W)`` tangent of each pixel's ray
    elevation, descending down each column; ``circle``, ``even_rows``, ``top_angle``,
    ``rows_per_radian``: their layout (:class:`homing_gym.render.raycast.Rays`; with columns
    once round the circle at even steps a span's columns are found by arithmetic, else
    by searching ``beta``; with rows even in elevation and the same in every column,
    segments that fall between two rows are dropped early). Writes ``hit (H, W)`` the
    triangle's index in the world mesh (``-1``: nothing) and ``weights (H, W, 3)`` the
    barycentric weights of the hit where the triangle is ``weighted`` (``(N,)`` bool,
    by mesh index: the shader needs them, for a texture or a shadow; elsewhere left as
    they were); ``depth (W, H)`` is scratch (the nearest hit's horizontal distance so
    far, column by column like the loops below), overwritten. Returns ``m`` and writes
    ``drawn[:m]`` (``drawn (N,)``): every triangle that won a pixel at some point, once
    (a superset of those in ``hit``). Of two hits at the same distance the triangle
    with the lower index wins, whatever order the triangles are cast in.

    Per group of triangles, three passes: their bearing spans, all at once
    (:func:`triangle_spans`); the pairs of a triangle and a column in its span, cut
    :data:`CHUNK` at a time (:func:`_cut_columns`); then their rows (:func:`_fill_rows`).
    Occlusion culling (a panorama, in a world with cells): the large triangles and the
    cells within :data:`NEAR_CELLS` first, then the other cells by their distance (front
    to back), skipping what is hidden below the rows already covered by something nearer
    (:func:`_uncovered`): a cell's triangles that stand too low in all its columns
    (:func:`_first_uncovered`), a triangle in a column where it does, and a pair's
    covered rows (:func:`_fill_rows`). Every test is conservative: the pixels are those
    of casting every triangle (tested).
    """
    H, W = tan_elev.shape
    N, C, L = corners.shape[1], box.shape[0], reach.shape[0]
    depth[:] = np.inf
    hit[:] = -1
    cos_b = np.cos(yaw + beta)
    sin_b = np.sin(yaw + beta)
    # columns per radian if evenly spaced: where the searches for a bearing start
    per_radian = (W - 1) / (beta[0] - beta[W - 1]) if W > 1 else 0.0
    step = 2 * math.pi / W
    ranges = np.empty((4, N), np.int32)          # (first, count) of up to two column runs
    M = 0 if circle else N                        # spans found by search
    lo, hi, kind = np.empty(M), np.empty(M), np.empty(M, np.int8)
    p = np.empty(13 * CHUNK)
    triangle, column = np.empty(CHUNK, np.int64), np.empty(CHUNK, np.int64)
    pair_level = np.empty(CHUNK, np.int64)
    cut = np.empty(15 * CHUNK)
    seen = np.empty(N, np.int64)
    listed = np.zeros(N, np.bool_)
    ox, oy, oz = origin[0], origin[1], origin[2]
    cull = circle and even_rows and C > 0
    level, near, far, by_level = _cells_by_level(box, reach, ox, oy, C if cull else 0)
    bound = np.full((L if cull else 0, W), H, np.int64)   # covered rows (:func:`_uncovered`)
    n = shown = 0
    for q in range(-1, C if cull else 0):         # the large triangles, then the cells
        lv, k1 = -1, N
        if q < 0:
            k0, k1 = (start[0], start[1]) if cull else (0, N)
        else:
            c = by_level[q]
            lv, k0, k1 = level[c], start[c + 1], start[c + 2]
            if lv >= 0:
                k0 = _first_uncovered(c, box, start, top, ox, oy, oz, yaw, beta[0], step,
                                      near[c], far[c], depth, tan_elev, reach, lv, bound)
        if circle:
            _circle_columns(corners, normals, closed, origin, yaw, beta[0], step, W, k0, k1,
                            ranges)
        else:
            triangle_spans(corners, normals, closed, origin, yaw, k0, k1, lo, hi, kind)
            _searched_columns(lo, hi, kind, beta, per_radian, k0, k1, ranges)
        # the triangles with columns, listed without a branch (a skip is mispredicted)
        m = 0
        for e in range(k1 - k0):
            u = np.uint64(k0 + e)         # unsigned: numba indexes without testing for < 0
            seen[m] = u
            m += ranges[1, u] > 0
        for k in seen[:m]:
            x0, y0, z0 = corners[0, k] - ox, corners[1, k] - oy, corners[2, k] - oz
            x1, y1, z1 = corners[3, k] - ox, corners[4, k] - oy, corners[5, k] - oz
            x2, y2, z2 = corners[6, k] - ox, corners[7, k] - oy, corners[8, k] - oz
            # beyond the first level: the tangent above which its rays pass (widened)
            tangent = np.inf
            if lv >= 0:
                tangent = _triangle_tangent(top[k] - oz, x0, y0, x1, y1, x2, y2)
            for r in range(0, 4, 2):
                for jj in range(ranges[r, k], ranges[r, k] + ranges[r + 1, k]):
                    j = jj - W if jj >= W else jj
                    if lv >= 0 and tangent < _uncovered(depth, tan_elev, reach, lv, j, bound):
                        continue                  # its rows there are all covered
                    p[n], p[CHUNK + n], p[2 * CHUNK + n] = x0, y0, z0
                    p[3 * CHUNK + n], p[4 * CHUNK + n], p[5 * CHUNK + n] = x1, y1, z1
                    p[6 * CHUNK + n], p[7 * CHUNK + n], p[8 * CHUNK + n] = x2, y2, z2
                    p[_COS * CHUNK + n], p[_SIN * CHUNK + n] = cos_b[j], sin_b[j]
                    if not even_rows:
                        p[_TOP_ANGLE * CHUNK + n] = top_angle[j]
                        p[_ROWS_PER_RADIAN * CHUNK + n] = rows_per_radian[j]
                    triangle[n], column[n], pair_level[n] = index[k], j, lv
                    n += 1
                    if n == CHUNK:
                        _cut_columns(n, p, H, even_rows, top_angle[0], rows_per_radian[0], cut)
                        shown = _fill_rows(n, triangle, column, pair_level, cut, tan_elev,
                                           even_rows, weighted, hit, weights, depth, bound,
                                           C > 0, listed, drawn, shown)
                        n = 0
    _cut_columns(n, p, H, even_rows, top_angle[0], rows_per_radian[0], cut)
    return _fill_rows(n, triangle, column, pair_level, cut, tan_elev, even_rows, weighted, hit,
                      weights, depth, bound, C > 0, listed, drawn, shown)


@njit(cache=True, error_model="numpy", inline="always")
def _box_distances(x0: float, y0: float, x1: float, y1: float):
    """``(near, far)``: the horizontal distances from the origin to the nearest and the
    farthest point of the box ``x0 <= x <= x1, y0 <= y <= y1``, a little widened."""
    dx, dy = max(max(x0, -x1), 0.0), max(max(y0, -y1), 0.0)
    fx, fy = max(-x0, x1), max(-y0, y1)
    return (math.sqrt(dx * dx + dy * dy) * (1 - _OCCLUSION_SLACK),
            math.sqrt(fx * fx + fy * fy) * (1 + _OCCLUSION_SLACK))


@njit(cache=True, error_model="numpy", inline="always")
def _top_tangent(rise: float, near: float, far: float) -> float:
    """An upper bound (a little widened) of the elevation tangent, from the origin, of
    a point at most ``rise`` above it and ``near`` to ``far`` away horizontally
    (``near > 0``)."""
    tangent = rise / (near if rise > 0.0 else far)
    return tangent + _OCCLUSION_SLACK * (1.0 + abs(tangent))


@njit(cache=True, error_model="numpy", nogil=True)
def _triangle_tangent(rise: float, x0: float, y0: float, x1: float, y1: float, x2: float,
                      y2: float) -> float:
    """:func:`_top_tangent` of a triangle with corners ``(x0, y0)``, ... (relative to the
    camera) rising at most ``rise`` above the camera."""
    near, far = _box_distances(min(min(x0, x1), x2), min(min(y0, y1), y2),
                               max(max(x0, x1), x2), max(max(y0, y1), y2))
    return _top_tangent(rise, near, far)


@njit(cache=True, error_model="numpy", nogil=True)
def _uncovered(depth: np.ndarray, tan: np.ndarray, reach: np.ndarray, lv: int, j: int,
               bound: np.ndarray) -> float:
    """The tangent of the lowest row of column ``j`` (``inf`` if none) below which
    every row down to the image's bottom has a hit nearer than ``reach[lv]``:
    ``bound[lv, j]``, the first such row, moved up past those covered since it was last
    asked (depths only shrink)."""
    r = bound[lv, j]
    while r > 0 and depth[j, r - 1] < reach[lv]:
        r -= 1
    bound[lv, j] = r
    return tan[r - 1, 0] if r > 0 else np.inf


@njit(cache=True, error_model="numpy", nogil=True)
def _cells_by_level(box: np.ndarray, reach: np.ndarray, ox: float, oy: float, C: int):
    """``(level, near, far, by_level)`` of the first ``C`` cells seen from ``(ox, oy)``:
    the occlusion level each is tested at (the last of :attr:`Triangles.reach` within
    its distance; -1 within the first: not tested), lower and upper bounds of the
    distance to its triangles (a little widened), and the cells in the order of their
    levels."""
    L = reach.shape[0]
    level, near, far = np.empty(C, np.int64), np.empty(C), np.empty(C)
    for c in range(C):
        near[c], far[c] = _box_distances(box[c, 0] - ox, box[c, 1] - oy, box[c, 2] - ox,
                                         box[c, 3] - oy)
        lv = -1
        if near[c] >= reach[0]:
            lv = min(int(math.log(near[c] / reach[0]) / math.log(LEVEL_FACTOR)), L - 1)
            while lv > 0 and reach[lv] > near[c]:
                lv -= 1
        level[c] = lv
    first = np.zeros(L + 2, np.int64)          # counted, then placed: a counting sort
    for c in range(C):
        first[level[c] + 2] += 1
    for lv in range(L + 1):
        first[lv + 1] += first[lv]
    by_level = np.empty(C, np.int64)
    for c in range(C):
        by_level[first[level[c] + 1]] = c
        first[level[c] + 1] += 1
    return level, near, far, by_level


@njit(cache=True, error_model="numpy", inline="always")
def _first_uncovered(c: int, box: np.ndarray, start: np.ndarray, top: np.ndarray, ox: float,
                     oy: float, oz: float, yaw: float, first: float, step: float, near: float,
                     far: float, depth: np.ndarray, tan: np.ndarray, reach: np.ndarray,
                     lv: int, bound: np.ndarray) -> int:
    """The first triangle of cell ``c`` (its triangles in the order of their tops) that
    might be seen from ``(ox, oy, oz)``: those before it stand wholly below the rows
    covered nearer than ``reach[lv]`` (:func:`_uncovered`) in every column the cell
    spans (``W`` once round the circle at bearings ``first - j * step``). ``near``,
    ``far``: lower and upper bounds of the distance to any point of the cell."""
    x0, y0, x1, y1 = box[c, 0] - ox, box[c, 1] - oy, box[c, 2] - ox, box[c, 3] - oy
    # the bearings of the box's corners, relative to the first one's
    d1 = _approx_atan2(x0 * y0 - y0 * x1, x0 * x1 + y0 * y0)
    d2 = _approx_atan2(x0 * y1 - y0 * x1, x0 * x1 + y0 * y1)
    d3 = _approx_atan2(x0 * y1 - y0 * x0, x0 * x0 + y0 * y1)
    a0 = _approx_atan2(y0, x0) - yaw
    a0 -= 2 * math.pi * np.floor((a0 + math.pi) * (0.5 / math.pi))
    lo = a0 + min(min(d1, d2), min(d3, 0.0)) - _ATAN_SLACK
    hi = a0 + max(max(d1, d2), max(d3, 0.0)) + _ATAN_SLACK
    j0 = int(np.ceil((first - hi) / step - _INDEX_SLACK))
    j1 = int(np.floor((first - lo) / step + _INDEX_SLACK)) + 1
    W = depth.shape[0]
    lowest = np.inf
    for jj in range(j0, j1):
        lowest = min(lowest, _uncovered(depth, tan, reach, lv, jj % W, bound))
    k, end = start[c + 1], start[c + 2]
    while k < end and _top_tangent(top[k] - oz, near, far) < lowest:
        k += 1
    return k


@njit(cache=True, error_model="numpy", nogil=True)
def _circle_columns(corners: np.ndarray, normals: np.ndarray, closed: np.ndarray,
                    origin: np.ndarray, yaw: float, first: float, step: float, W: int,
                    k0: int, k1: int, ranges: np.ndarray) -> None:
    """``ranges[:, t]`` for ``k0 <= t < k1``: the first column (in ``[0, W)``; the run
    may go past ``W - 1`` and wraps round to column 0) and the number of columns (at
    most ``W``) of each triangle's span (:func:`triangle_spans`; 0 for those skipped),
    then ``(0, 0)``, for ``W`` columns once round the circle at bearings ``first - j *
    step``; a little wider than the span (each column is tested exactly). Branch-free:
    vectorised."""
    for q in range(k1 - k0):
        t = np.uint64(k0 + q)     # unsigned: numba indexes without testing for < 0
        lo, hi, kind = _bearing_span(corners, normals, closed, t, origin[0], origin[1],
                                     origin[2], yaw)
        j0 = np.ceil((first - hi) / step - _INDEX_SLACK)           # whole numbers, as floats
        j1 = np.floor((first - lo) / step + _INDEX_SLACK) + 1.0
        count = min(max(j1 - j0, 0.0), float(W))
        j0 -= W * np.floor(j0 / W)                      # into [0, W): exact on whole numbers
        everywhere = kind == EVERYWHERE
        ranges[0, t] = 0 if everywhere else int(j0)
        ranges[1, t] = W if everywhere else (0 if kind == SKIP else int(count))
        ranges[2, t] = 0
        ranges[3, t] = 0


@njit(cache=True, error_model="numpy", nogil=True)
def _searched_columns(lo: np.ndarray, hi: np.ndarray, kind: np.ndarray, beta: np.ndarray,
                      per_radian: float, k0: int, k1: int, ranges: np.ndarray) -> None:
    """``ranges[:, t]`` for ``k0 <= t < k1``: ``(first, count)`` of up to two runs of
    the columns ``beta`` (any bearings, strictly descending) in each triangle's span,
    found by search."""
    W = beta.shape[0]
    for t in range(k0, k1):
        ranges[:, t] = 0
        if kind[t] == EVERYWHERE:
            ranges[0, t], ranges[1, t] = 0, W
            continue
        if kind[t] == SKIP:
            continue
        r = 0
        for shift in (-2 * math.pi, 0.0, 2 * math.pi):
            j0, j1 = _columns(beta, lo[t] + shift, hi[t] + shift, per_radian)
            if j1 > j0 and r < 4:
                ranges[r, t], ranges[r + 1, t] = j0, j1 - j0
                r += 2


@njit(cache=True, error_model="numpy", inline="always")
def _texel(atlas: np.ndarray, levels: np.ndarray, m: int, s: float, v: float):
    """Bilinear sample (wrapped) of mip level ``levels[m] = (offset, height, width)`` at
    texture coordinates ``(s, v)`` (``v`` bottom to top): ``(r, g, b)``, returned in
    registers rather than through memory. The level is stored with a border of one
    texel wrapped round from the opposite side (:func:`texel_offset`), so the four
    texels around any point are read without wrapping their indices; the indices are
    unsigned, so numba reads without testing them for negative values."""
    level = np.uint64(m)
    off, h, w = levels[level, 0], levels[level, 1], levels[level, 2]
    x = (s - np.floor(s)) * w - 0.5                  # in [-0.5, w - 0.5]
    y = (np.ceil(v) - v) * h - 0.5                   # rows run top to bottom
    xa, ya = int(math.floor(x)), int(math.floor(y))  # in [-1, w - 1], [-1, h - 1]
    fx, fy = x - xa, y - ya
    a = np.uint64(texel_offset(off, w, ya, xa))
    b = a + np.uint64(3)
    c = a + np.uint64(3 * (w + 2))
    d = c + np.uint64(3)
    one, two = np.uint64(1), np.uint64(2)
    return (_bilinear(atlas, a, b, c, d, fx, fy),
            _bilinear(atlas, a + one, b + one, c + one, d + one, fx, fy),
            _bilinear(atlas, a + two, b + two, c + two, d + two, fx, fy))


@njit(cache=True, error_model="numpy", inline="always")
def texel_offset(off: int, w: int, row: int, col: int) -> int:
    """Where texel ``(row, col)`` (from ``-1`` to the size: the border included) of a
    level ``w`` texels wide, stored from ``off`` with its border, starts in the atlas."""
    return off + 3 * ((row + 1) * (w + 2) + col + 1)


@njit(cache=True, error_model="numpy", inline="always")
def _bilinear(atlas: np.ndarray, a: int, b: int, c: int, d: int, fx: float, fy: float) -> float:
    """``atlas[a]``, ``[b]`` (the top row's two texels), ``[c]``, ``[d]`` (the bottom's)
    blended by the fractions ``fx`` across and ``fy`` down."""
    top = (1 - fx) * atlas[a] + fx * atlas[b]
    bottom = (1 - fx) * atlas[c] + fx * atlas[d]
    return (1 - fy) * top + fy * bottom


@njit(cache=True, error_model="numpy", nogil=True)
def lit_colors(colors: np.ndarray, normals: np.ndarray, tris: np.ndarray, closed: np.ndarray,
               light: np.ndarray, ambient: float, diffuse: float, origin: np.ndarray,
               which: np.ndarray, lit: np.ndarray) -> None:
    """Writes ``lit[t]`` for each triangle ``t`` in ``which``: its colour times
    ``ambient + diffuse * max(0, n . l)`` seen from ``origin``. Lambert with the unit
    light direction ``l``, ``n`` the triangle's normal turned towards the camera (a face
    turned away from the light gets the ambient term alone). A ``closed`` triangle is
    only ever seen from outside (:func:`cast_columns` skips it otherwise), so its ``n``
    is the outward normal wherever the camera is: its colour depends on the light alone
    and can be kept from image to image."""
    for t in which:
        towards = 1.0
        cos_light = 0.0
        for d in range(3):
            cos_light += normals[t, d] * light[d]
        if not closed[t]:
            towards = 0.0
            for d in range(3):
                towards += normals[t, d] * (origin[d] - tris[t, 0, d])
        if towards < 0.0:
            cos_light = -cos_light
        elif towards == 0.0:
            cos_light = 0.0
        factor = ambient + diffuse * max(cos_light, 0.0)
        for c in range(3):
            lit[t, c] = colors[t, c] * factor


#: float32 constants of the final quantisation (the same arithmetic as a float32 image
#: ``* 255 + 0.5`` truncated to uint8, i.e. rounded half up).
_SCALE_255 = np.float32(255.0)
_HALF = np.float32(0.5)


@njit(cache=True, error_model="numpy", nogil=True)
def shade(hit: np.ndarray, weights: np.ndarray, base: np.ndarray, texture: np.ndarray,
          uvs: np.ndarray, atlas: np.ndarray, levels: np.ndarray, first_level: np.ndarray,
          texel_density: np.ndarray, tris: np.ndarray, normals: np.ndarray,
          origin: np.ndarray, ray_spacing: float, sky: np.ndarray, out: np.ndarray,
          shaded: np.ndarray, shadow_depth: np.ndarray, shadow_axes: np.ndarray,
          shadow_origin: np.ndarray, shadow_cell: float) -> None:
    """The image ``out (H/k, W/k, 3)`` (uint8) from the ``(H, W)`` rays' hits: each
    pixel the mean of its ``k x k`` rays' colours (``k = H / out.shape[0]``), each colour
    the sky where nothing was hit (``sky (h, w, 3)``: ray ``(i, j)``'s sky is
    ``sky[i, j]``, along an axis of length 1 the same for every ray), else the triangle's lit colour ``base`` times its
    texture (``u`` left to right, ``v`` bottom to top, wrapped), clipped to ``[0, 1]``.
    The mean is summed in float32 in row-major order (for ``k = 2`` bit for bit OpenCV's
    box average, ``INTER_AREA``), then scaled to 0-255 and rounded half up.

    Textures are filtered like a camera's pixel (trilinear mip-mapping): the ray's
    footprint on the surface, ``r * ray_spacing / |cos(incidence)|`` metres (``r`` the
    ray's length, ``ray_spacing`` the angle between neighbouring rays, radians; the cosine
    at least 0.1), times the triangle's ``texel_density`` (texels per metre at full
    resolution) gives the level of detail ``log2`` of that many texels; the two mip levels
    around it are sampled bilinearly and blended. ``atlas`` holds every level of every
    texture flattened one after another, each with a border of one texel wrapped round
    (:func:`texel_offset`); ``levels[m] = (offset, height, width)`` of mip
    level ``m``, texture ``k``'s levels from ``first_level[k]`` to ``first_level[k + 1]``
    (full resolution first, each half the size of the one before). A face whose UVs cover
    no area (one texel for the whole face) takes that texel.

    Cast shadows (:mod:`homing_gym.render.shadows`; off when ``shadow_depth`` is empty): a point
    in the shadow of the map takes ``shaded[t]`` (the ambient light alone) instead of
    ``base[t]``.

    Each ray column is shaded in two passes: lit colours, texture coordinates and levels
    of detail (:func:`_lit_rays`), then the texture samples of the rays that need them
    (:func:`_textured_rays`). A textured ray is a long chain of dependent steps; cut in
    two short loops, the core works on several rays at once (the arithmetic, so every
    pixel, is the same as in one loop)."""
    rows, cols = out.shape[0], out.shape[1]
    H = hit.shape[0]
    k = H // rows
    mean = np.float32(1.0 / (k * k))
    zero = np.float32(0.0)
    color = np.empty((k, H, 3), np.float32)    # the colours of one pixel column's rays
    sample = np.empty((H, 6))     # (s, v, lod, lit r, g, b) of a ray column's textured rays
    textured = np.empty(H, np.int64)           # and their rows
    for jo in range(cols):
        for a in range(k):
            j = jo * k + a
            n = _lit_rays(hit, weights, base, texture, uvs, texel_density, tris, normals,
                          origin, ray_spacing, sky, shaded, shadow_depth, shadow_axes,
                          shadow_origin, shadow_cell, j, color[a], sample, textured)
            _textured_rays(n, textured, sample, hit, j, texture, atlas, levels, first_level,
                           texel_density, color[a])
        for io in range(rows):
            acc_r, acc_g, acc_b = zero, zero, zero        # in registers, not an array
            for i in range(io * k, io * k + k):
                for a in range(k):
                    acc_r += color[a, i, 0]
                    acc_g += color[a, i, 1]
                    acc_b += color[a, i, 2]
            out[io, jo, 0] = np.uint8(acc_r * mean * _SCALE_255 + _HALF)
            out[io, jo, 1] = np.uint8(acc_g * mean * _SCALE_255 + _HALF)
            out[io, jo, 2] = np.uint8(acc_b * mean * _SCALE_255 + _HALF)


@njit(cache=True, error_model="numpy", inline="always")
def _lit_rays(hit: np.ndarray, weights: np.ndarray, base: np.ndarray, texture: np.ndarray,
              uvs: np.ndarray, texel_density: np.ndarray, tris: np.ndarray,
              normals: np.ndarray, origin: np.ndarray, ray_spacing: float, sky: np.ndarray,
              shaded: np.ndarray, shadow_depth: np.ndarray, shadow_axes: np.ndarray,
              shadow_origin: np.ndarray, shadow_cell: float, j: int, color: np.ndarray,
              sample: np.ndarray, textured: np.ndarray) -> int:
    """First pass of :func:`shade` over ray column ``j``: ``color[i]`` the sky, or the
    lit (or shadowed) colour of the triangle hit, clipped; for the rays on a texture
    instead their rows in ``textured`` and in ``sample`` their texture coordinates,
    level of detail and lit colour. Returns how many rays are on a texture."""
    shadows = shadow_depth.size > 0
    n = 0
    for i in range(hit.shape[0]):
        t = hit[i, j]
        if t < 0:
            si, sj = (i if sky.shape[0] > 1 else 0), (j if sky.shape[1] > 1 else 0)
            color[i, 0], color[i, 1], color[i, 2] = sky[si, sj, 0], sky[si, sj, 1], sky[si, sj, 2]
            continue
        r, g, b = base[t, 0], base[t, 1], base[t, 2]
        tex = texture[t]
        px = py = pz = 0.0
        if tex >= 0 or shadows:
            for c in range(3):
                px += weights[i, j, c] * tris[t, c, 0]
                py += weights[i, j, c] * tris[t, c, 1]
                pz += weights[i, j, c] * tris[t, c, 2]
        if shadows and (r, g, b) != (shaded[t, 0], shaded[t, 1], shaded[t, 2]):
            facing = (normals[t, 0] * shadow_axes[2, 0] + normals[t, 1] * shadow_axes[2, 1]
                      + normals[t, 2] * shadow_axes[2, 2])
            if in_shadow(shadow_depth, shadow_axes, shadow_origin, shadow_cell,
                         px, py, pz, facing):
                r, g, b = shaded[t, 0], shaded[t, 1], shaded[t, 2]
        if tex >= 0:
            s = v = 0.0
            for c in range(3):
                s += weights[i, j, c] * uvs[t, c, 0]
                v += weights[i, j, c] * uvs[t, c, 1]
            dx, dy, dz = px - origin[0], py - origin[1], pz - origin[2]
            length = math.sqrt(dx * dx + dy * dy + dz * dz)
            facing = abs(normals[t, 0] * dx + normals[t, 1] * dy + normals[t, 2] * dz)
            cos_in = max(facing / max(length, 1e-9), 0.1)
            texels = length * ray_spacing / cos_in * texel_density[t]
            sample[n, 0], sample[n, 1] = s, v
            sample[n, 2] = math.log2(texels) if texels > 1.0 else 0.0
            sample[n, 3], sample[n, 4], sample[n, 5] = r, g, b
            textured[n] = i
            n += 1
        else:
            _set_clipped(color, i, r, g, b)
    return n


@njit(cache=True, error_model="numpy", inline="always")
def _textured_rays(n: int, textured: np.ndarray, sample: np.ndarray, hit: np.ndarray, j: int,
                   texture: np.ndarray, atlas: np.ndarray, levels: np.ndarray,
                   first_level: np.ndarray, texel_density: np.ndarray,
                   color: np.ndarray) -> None:
    """Second pass of :func:`shade`: ``color`` of the first ``n`` rays listed in
    ``textured`` (rows of ray column ``j``), their lit colour times their texture's
    filtered colour, clipped."""
    for q in range(n):
        i = textured[q]
        t = hit[i, j]
        tex = texture[t]
        s, v, lod = sample[q, 0], sample[q, 1], sample[q, 2]
        top = first_level[tex + 1] - first_level[tex] - 1
        lod = min(lod, float(top))
        m = int(lod)
        frac = lod - m
        base_level = first_level[tex]
        if texel_density[t] == 0.0:      # one texel spread over the face (no UVs)
            off, h, w = (levels[base_level, 0], levels[base_level, 1],
                         levels[base_level, 2])
            col = min(max(int((s % 1.0) * w), 0), w - 1)
            row = min(max(int((1.0 - v % 1.0) * h), 0), h - 1)
            at = texel_offset(off, w, row, col)
            nr, ng, nb = float(atlas[at]), float(atlas[at + 1]), float(atlas[at + 2])
        else:
            nr, ng, nb = _texel(atlas, levels, base_level + m, s, v)
        if frac > 0.0 and m < top and texel_density[t] > 0.0:
            fr, fg, fb = _texel(atlas, levels, base_level + m + 1, s, v)
            nr = (1 - frac) * nr + frac * fr
            ng = (1 - frac) * ng + frac * fg
            nb = (1 - frac) * nb + frac * fb
        _set_clipped(color, i, sample[q, 3] * nr, sample[q, 4] * ng, sample[q, 5] * nb)


@njit(cache=True, error_model="numpy", inline="always")
def _set_clipped(color: np.ndarray, i: int, r: float, g: float, b: float) -> None:
    """``color[i] = (r, g, b)`` clipped to ``[0, 1]`` (stored in float32, the precision
    :func:`shade` sums them in)."""
    color[i, 0], color[i, 1], color[i, 2] = (min(max(r, 0.0), 1.0), min(max(g, 0.0), 1.0),
                                             min(max(b, 0.0), 1.0))
