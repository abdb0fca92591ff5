"""Routes from files: ``route="path/to/route.csv"`` (or ``.npy``, ``.json``) for
RouteFollowing-v0, as well as a list of points.

A route file holds one point per row, ``x, y`` or ``x, y, yaw`` (metres, radians
counter-clockwise from +x; every row the same columns):

* ``.csv``: comma-separated numbers, one point per line; blank lines and lines starting
  with ``#`` are skipped, and a first line without numbers (``x,y,yaw``) is a header;
* ``.npy``: a numeric array of shape (N, 2) or (N, 3), read with
  ``numpy.load(allow_pickle=False)``: a file holding Python objects is refused, so that
  reading a route runs no code from it;
* ``.json``: a list of ``[x, y]`` or ``[x, y, yaw]`` lists.

From 2 to :data:`MAX_ROUTE_POINTS` points. Anything else is a ``ValueError`` naming the
file and, where one is at fault, the point. The route's own rules (consecutive points at
least 5 cm apart, clearance in the scene) are the task's, checked after loading.
"""

from __future__ import annotations

import csv
import json
import math
import numbers
import os
from collections.abc import Sequence
from typing import Any

import numpy as np

#: Most points a route file may hold.
MAX_ROUTE_POINTS = 10_000
#: Largest CSV or JSON route file read (bytes): 10,000 points need well under 1 MB.
MAX_FILE_BYTES = 16 * 2**20
FORMATS = (".csv", ".npy", ".json")


def load_route(route: Any) -> Any:
    """``route`` itself, or, for a path (``str`` or ``os.PathLike``), the points of the
    route file it names as an ``(N, 2)`` or ``(N, 3)`` float array."""
    if not isinstance(route, (str, os.PathLike)):
        return route
    path = os.fspath(route)
    suffix = os.path.splitext(path)[1].lower()
    if os.path.isdir(path):
        raise ValueError(f"route file {path!r} is a directory; give a {'/'.join(FORMATS)} file")
    if suffix not in FORMATS:
        raise ValueError(f"route file {path!r}: unknown format {suffix or '(no extension)'!r}; "
                         f"allowed: {', '.join(FORMATS)} (or give the route as a list of "
                         f"points)")
    try:
        if suffix == ".npy":
            rows = _npy_rows(path)
        else:
            if os.path.getsize(path) > MAX_FILE_BYTES:
                raise ValueError(f"route file {path!r} is larger than {MAX_FILE_BYTES} bytes")
            rows = _csv_rows(path) if suffix == ".csv" else _json_rows(path)
    except (OSError, UnicodeDecodeError) as err:
        raise ValueError(f"route file {path!r}: cannot read it ({err})") from None
    return _points(path, rows)


def _csv_rows(path: str) -> list[tuple[str, list]]:
    """``(where, fields)`` of every point line of a CSV file (at most one more than the
    bound, so that a huge file is not read to its end)."""
    rows: list[tuple[str, list]] = []
    with open(path, newline="") as f:
        reader, first = csv.reader(f), True
        for fields in reader:
            fields = [x.strip() for x in fields]
            if not any(fields) or fields[0].startswith("#"):
                continue
            values = [_number(x) for x in fields]
            header, first = first and all(isinstance(v, str) for v in values), False
            if not header:
                rows.append((f"line {reader.line_num}", values))
            if len(rows) > MAX_ROUTE_POINTS:
                break
    return rows


def _json_rows(path: str) -> list[tuple[str, Any]]:
    with open(path) as f:
        try:
            doc = json.load(f)
        except json.JSONDecodeError as err:
            raise ValueError(f"route file {path!r}: not valid JSON ({err})") from None
    if not isinstance(doc, list):
        raise ValueError(f"route file {path!r}: expected a JSON list of [x, y] or [x, y, yaw] "
                         f"points, got a {type(doc).__name__}")
    return [(f"item {k}", row) for k, row in enumerate(doc[:MAX_ROUTE_POINTS + 1])]


def _npy_rows(path: str) -> list[tuple[str, Any]]:
    try:
        array = np.load(path, allow_pickle=False, mmap_mode="r")
    except ValueError as err:
        raise ValueError(f"route file {path!r}: not a numeric .npy array ({err}); route files "
                         f"are read without unpickling") from None
    if not isinstance(array, np.ndarray) or array.dtype.kind not in "iuf" or array.ndim != 2:
        raise ValueError(f"route file {path!r}: expected a numeric array of shape (N, 2) or "
                         f"(N, 3), got {getattr(array, 'dtype', '?')} of shape "
                         f"{getattr(array, 'shape', '?')}")
    return [(f"row {k}", row.tolist()) for k, row in enumerate(array[:MAX_ROUTE_POINTS + 1])]


def _number(text: str) -> float | str:
    """``text`` as a float, or itself if it is no number."""
    try:
        return float(text)
    except ValueError:
        return text


def _points(path: str, rows: Sequence[tuple[str, Any]]) -> np.ndarray:
    """The rows as an ``(N, 2|3)`` float array; ``ValueError`` naming the file and the
    first bad point."""
    if len(rows) > MAX_ROUTE_POINTS:
        raise ValueError(f"route file {path!r} holds more than {MAX_ROUTE_POINTS} points")
    if len(rows) < 2:
        raise ValueError(f"route file {path!r} holds {len(rows)} point(s); a route needs at "
                         f"least two (the start, then the targets)")
    points: list[list[float]] = []
    for k, (where, row) in enumerate(rows):
        ok = (isinstance(row, (list, tuple)) and len(row) in (2, 3)
              and all(isinstance(v, numbers.Real) and not isinstance(v, bool)
                      and math.isfinite(v) for v in row))
        if not ok:
            raise ValueError(f"route file {path!r}, point {k} ({where}): expected x, y or "
                             f"x, y, yaw as finite numbers (metres, radians), got {row!r}")
        if points and len(row) != len(points[0]):
            raise ValueError(f"route file {path!r}, point {k} ({where}): {len(row)} columns, "
                             f"but point 0 has {len(points[0])}; every point needs the same")
        points.append([float(v) for v in row])
    return np.array(points, dtype=np.float64)
