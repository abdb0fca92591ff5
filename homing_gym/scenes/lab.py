"""``lab``: the laboratory of Bekris, Argyros & Kavraki's experiments (§5, Fig. 9).

A 6 m x 5 m room (x in [-3, 3], y in [-2.5, 2.5]) with 2.5 m walls of grey brick and
concrete (tall enough that their top edge, which KLT corners would slide along, is
rarely in view). Three distinctly coloured poster columns (red, green, blue; radius 0.1 m,
0.7 m high) stand free in the room as the landmarks ``L1``-``L3`` of the bearing-only
laws; everyday objects give image corners for KLT tracking: a door, a desk, a pile of
boxes, a shelf, a cabinet, a bin and three dark checkered boards on the walls.

The paper's panels were flat posters seen from the workspace; ours are four-sided in
effect (cylinders), so that the centroid of the blob is the bearing of the column's
axis from everywhere, including from the wedges ``H^`` behind the landmarks. Nothing
else in the room is strongly saturated in the three poster hues
(:data:`homing_baselines.blobs.LAB_COLORS`).

``scene.metadata``:

* ``"landmarks"``: ``{"red": (x, y), "green": ..., "blue": ...}``, the column axes (m);
* ``"marked"``: the six marked goal positions ``A``-``F`` (m), chosen as in Fig. 9b:
  ``A`` inside the landmark triangle ``T^``, ``F`` in ``C^ - T^`` (inside the circle
  through the landmarks, outside the triangle), ``C`` and ``D`` in ``H^`` (behind
  ``L1`` and ``L2``), ``B`` and ``E`` in the rest of the plane. Each lies at least
  0.2 m from the boundaries of its region
  (``tests/homing_baselines/test_bearing_controllers.py`` checks with
  :func:`homing_baselines.bearing_sim.region`).
"""

from __future__ import annotations

import math

from homing_gym.scenes.base import Landmark, Scene, Wall

HALF_X, HALF_Y, HEIGHT, WALL_T = 3.0, 2.5, 2.5, 0.05
POSTER_RADIUS, POSTER_HEIGHT = 0.1, 0.7
#: Landmark colours (RGBA) and column positions (m): L1 red, L2 green, L3 blue.
POSTERS = {"red": ((0.85, 0.08, 0.08, 1.0), (-0.9, -0.6)),
           "green": ((0.1, 0.7, 0.15, 1.0), (1.1, -0.7)),
           "blue": ((0.1, 0.2, 0.9, 1.0), (0.1, 1.0))}
#: The six marked goal positions of Fig. 9b (m).
MARKED = {"A": (0.1, -0.1), "B": (-2.2, 1.2), "C": (-2.0, -1.6), "D": (2.2, -1.5),
          "E": (2.0, 1.6), "F": (0.15, -0.96)}
CARDBOARD = (0.62, 0.5, 0.36, 1.0)


def _wall_box(x: float, y: float, width: float, depth: float, height: float, base: float,
              yaw: float = 0.0, **kwargs) -> Landmark:
    return Landmark(position=(x, y), shape="box", extent=(width, depth), height=height,
                    base=base, yaw=yaw, **kwargs)


def lab_scene() -> Scene:
    """The fixed ``lab`` scene."""
    hx, hy, t = HALF_X + WALL_T / 2, HALF_Y + WALL_T / 2, WALL_T
    walls = (
        Wall((-HALF_X, hy), (HALF_X, hy), HEIGHT, t, texture="bricks_grey"),
        Wall((-HALF_X, -hy), (HALF_X, -hy), HEIGHT, t, texture="concrete"),
        Wall((-hx, -HALF_Y), (-hx, HALF_Y), HEIGHT, t, texture="concrete"),
        Wall((hx, -HALF_Y), (hx, HALF_Y), HEIGHT, t, texture="bricks_grey"),
    )
    posters = tuple(
        Landmark(position=pos, radius=POSTER_RADIUS, height=POSTER_HEIGHT, color=color,
                 name=f"poster_{name}")
        for name, (color, pos) in POSTERS.items())
    objects = (
        # a door in the north wall, a board on the west wall, a shelf on the east wall
        _wall_box(-1.2, HALF_Y - 0.03, 0.9, 0.05, 1.1, 0.0, color=(1, 1, 1, 1),
                  texture="wood_light", name="door"),
        _wall_box(-HALF_X + 0.025, 0.4, 0.9, 0.03, 0.5, 0.2, yaw=math.pi / 2,
                  color=(1, 1, 1, 1), texture="checker_dark", name="board"),
        _wall_box(HALF_X - 0.16, 0.2, 1.0, 0.3, 0.9, 0.0, yaw=math.pi / 2,
                  color=(0.45, 0.35, 0.3, 1.0), name="shelf"),
        _wall_box(1.3, HALF_Y - 0.015, 0.8, 0.03, 0.5, 0.3, color=(1, 1, 1, 1),
                  texture="checker_dark", name="board_north"),
        _wall_box(1.8, -HALF_Y + 0.015, 0.8, 0.03, 0.5, 0.3, color=(1, 1, 1, 1),
                  texture="checker_dark", name="board_south"),
        _wall_box(HALF_X - 0.015, -1.4, 0.7, 0.03, 0.6, 0.25, yaw=math.pi / 2,
                  color=(1, 1, 1, 1), texture="wood_light", name="cabinet_door"),
        # a desk along the south wall, a pile of boxes in the north-east corner, a bin
        _wall_box(-0.3, -HALF_Y + 0.35, 1.2, 0.6, 0.45, 0.0, color=(1, 1, 1, 1),
                  texture="wood_light", name="desk"),
        _wall_box(2.55, 2.1, 0.5, 0.5, 0.35, 0.0, color=CARDBOARD, name="box_low"),
        _wall_box(2.6, 2.15, 0.35, 0.35, 0.3, 0.35, yaw=0.3, color=(0.7, 0.6, 0.45, 1.0),
                  name="box_top"),
        _wall_box(1.9, 2.25, 0.4, 0.4, 0.3, 0.0, yaw=-0.2, color=(0.5, 0.42, 0.32, 1.0),
                  name="box_side"),
        Landmark(position=(-2.7, -2.2), radius=0.15, height=0.4, color=(0.3, 0.3, 0.32, 1.0),
                 name="bin"),
    )
    return Scene(
        name="lab",
        bounds=((-HALF_X, -HALF_Y), (HALF_X, HALF_Y)),
        walls=walls,
        landmarks=posters + objects,
        floor_color=(1.0, 1.0, 1.0, 1.0),
        floor_texture="floor_tiles",
        metadata={"landmarks": {name: pos for name, (_, pos) in POSTERS.items()},
                  "marked": dict(MARKED)},
    )
