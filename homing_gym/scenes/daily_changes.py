"""Daily changes to a scene: small objects moved, removed or added between the day the
robot was taught and the day it runs (Shiraishi & Sawasaki §2, problem (b-1): "details
of the surroundings in an ordinary household are temporally unstable due to daily
activities of the residents").

:func:`daily_changes` works on any scene that lists its movable objects in
``metadata["small_objects"]`` and its floor plan in ``metadata["rooms"]`` (like
``house``); objects are never put where they would block ``metadata["paths"]`` or the
``metadata["work_locations"]``.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from homing_gym.scenes.base import Landmark, Scene, clearance
from homing_gym.validation import is_real

#: Free distance (m) kept between a changed object and a path or work location.
PATH_MARGIN = 0.45
#: How far (m) a moved object may go, uniformly in x and y.
MOVE_RANGE = 0.4
#: Colours of added objects (RGBA).
ADDED_COLORS = ((0.9, 0.75, 0.1, 1.0), (0.2, 0.6, 0.8, 1.0), (0.8, 0.3, 0.6, 1.0),
                (0.3, 0.7, 0.3, 1.0))


def _segment_distance(p, a, b) -> float:
    ab = np.subtract(b, a)
    t = float(np.clip(np.dot(np.subtract(p, a), ab) / max(float(ab @ ab), 1e-12), 0, 1))
    return float(math.dist(p, np.add(a, t * ab)))


def _keeps_paths_free(scene: Scene, lm: Landmark) -> bool:
    """Whether ``lm`` stands clear of the scene's paths and work locations and of
    every other object (its footprint radius plus :data:`PATH_MARGIN`)."""
    reach = lm.footprint_radius + PATH_MARGIN
    for pts in scene.metadata.get("paths", {}).values():
        if any(_segment_distance(lm.position, a, b) < reach for a, b in zip(pts[:-1], pts[1:])):
            return False
    if any(math.dist(lm.position, w[:2]) < reach
           for w in scene.metadata.get("work_locations", {}).values()):
        return False
    return clearance(scene, lm.position) >= lm.footprint_radius + 0.05


def daily_changes(scene: Scene, rng: np.random.Generator, strength: float) -> Scene:
    """``scene`` after a day of living in it. ``strength`` in [0, 1]: each small object is
    removed with probability ``strength / 3`` or else moved (up to ``MOVE_RANGE`` m and a
    new yaw) with probability ``strength / 2``; ``round(3 * strength)`` new small objects
    (boxes and cylinders 10-25 cm across, 10-35 cm tall) are put down at random free
    places of the rooms. 0 returns the scene unchanged."""
    if not (is_real(strength) and 0 <= strength <= 1):
        raise ValueError(f"daily change strength must be in [0, 1], got {strength!r}")
    if strength == 0:
        return scene
    for key in ("small_objects", "rooms"):
        if key not in scene.metadata:
            raise ValueError(f"scene {scene.name!r} has no metadata[{key!r}]; daily changes "
                             f"need a scene like 'house'")
    movable = set(scene.metadata["small_objects"])
    fixed = [lm for lm in scene.landmarks if lm.name not in movable]
    base = replace(scene, landmarks=tuple(fixed))
    kept: list[Landmark] = []
    for lm in (lm for lm in scene.landmarks if lm.name in movable):
        u = rng.random()
        if u < strength / 3:
            continue
        if u < strength / 3 + strength / 2:
            lm = _placed(replace(base, landmarks=tuple(fixed + kept)), rng, lm, around=True)
        kept.append(lm)
    for i in range(int(round(3 * strength))):
        size = rng.uniform(0.1, 0.25)
        new = Landmark((0.0, 0.0), shape="box" if rng.random() < 0.5 else "cylinder",
                       radius=size / 2, extent=(size, rng.uniform(0.1, 0.25)),
                       height=float(rng.uniform(0.1, 0.35)),
                       color=ADDED_COLORS[int(rng.integers(len(ADDED_COLORS)))],
                       name=f"small_added{i}")
        kept.append(_placed(replace(base, landmarks=tuple(fixed + kept)), rng, new,
                            around=False))
    return replace(scene, landmarks=tuple(fixed + kept))


def _placed(scene: Scene, rng: np.random.Generator, lm: Landmark, around: bool,
            tries: int = 200) -> Landmark:
    """``lm`` at a random free place: near its own position (``around``) or anywhere in
    the rooms; unchanged if no free place is found."""
    rooms = scene.metadata["rooms"]
    for _ in range(tries):
        if around:
            xy = np.add(lm.position, rng.uniform(-MOVE_RANGE, MOVE_RANGE, 2))
        else:
            (x0, y0), (x1, y1) = rooms[int(rng.integers(len(rooms)))]
            xy = (rng.uniform(x0, x1), rng.uniform(y0, y1))
        moved = replace(lm, position=(float(xy[0]), float(xy[1])),
                        yaw=float(rng.uniform(-math.pi, math.pi)))
        (xmin, ymin), (xmax, ymax) = scene.bounds
        hx, hy = moved.footprint_half_size
        inside = xmin <= xy[0] - hx and xy[0] + hx <= xmax and ymin <= xy[1] - hy \
            and xy[1] + hy <= ymax
        if inside and _keeps_paths_free(scene, moved):
            return moved
    return lm
