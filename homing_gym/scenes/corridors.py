"""``corridors``: rooms and a corridor with barcoded self-similar landmarks on the walls
(Briggs, Scharstein et al. 2000; the scene of ``LandmarkNavigation-v0``).

An 8 x 6 m floor: four 4 x 2.4 m rooms, two south (A, B) and two north (C, D) of a
1.2 m wide corridor running east-west (y from 2.4 to 3.6 m), each room opening onto it
through a 1.2 m door. Walls are 1.2 m high and light grey, the floor light grey
(the detector's barcode reader needs light surroundings, see
:mod:`homing_baselines.selfsimilar_detector`). Fourteen landmark panels
(:func:`wall_panel`, :mod:`homing_gym.selfsimilar`, ids 0-13) hang on the walls with
the pattern centred at camera height: two in each room on the wall facing its door, one
on each end wall of the corridor and one opposite each door (see :data:`PANELS`: the
visibility graph is connected). ``scene.metadata``:

* ``"landmarks"``: ``{id: (x, y, yaw_in)}``, the centre of each panel's front face and
  the direction (radians) of its normal into the room;
* ``"rooms"``: the free rectangles ``((xmin, ymin), (xmax, ymax))`` where episodes
  start (the floor plan; everything inside ``bounds`` belongs to one of them).
"""

from __future__ import annotations

import math

from homing_gym.scenes.base import Landmark, Scene, Wall
from homing_gym.selfsimilar import DEFAULT_P, PanelLayout, panel_texture_path

WIDTH, DEPTH = 8.0, 6.0
CORRIDOR = (2.4, 3.6)
DOOR = 1.2
WALL_HEIGHT, WALL_T = 1.2, 0.05
WALL_COLOR = (0.9, 0.9, 0.88, 1.0)
FLOOR_COLOR = (0.75, 0.75, 0.73, 1.0)
PANEL_DEPTH = 0.02
#: Height (m) of the pattern's centre above the floor: the camera's height.
PANEL_CENTRE_HEIGHT = 0.30
#: Door centres (x) on the south (rooms A, B) and north (C, D) corridor walls.
DOORS_SOUTH = (2.0, 6.1)
DOORS_NORTH = (3.0, 5.0)
#: Landmark panels: (id, x, y, direction of the wall normal into the room, degrees).
#: (x, y) is on the wall surface, the centre of the panel. Each room's two panels hang on
#: the wall facing its door, 0.6 m either side of the door's axis; each door faces a
#: corridor panel on the opposite corridor wall. From a room panel's standing place (1 m
#: out) the robot sees that corridor panel through the door and from the corridor
#: panel's standing place (in the doorway) both room panels; the corridor's end panels
#: see along the corridor. So every panel is reachable from every other one over the
#: visibility graph (§4.1), as in the paper's environment, where landmarks are seen from
#: room to corridor and along it (checked on rendered views by
#: ``python -m homing_train.figures.selfsimilar layout`` and ``tests/homing_baselines/test_selfsimilar_render.py``).
PANELS = (
    (0, 1.4, 0.0, 90), (1, 2.6, 0.0, 90),          # room A (south-west)
    (2, 5.5, 0.0, 90), (3, 6.7, 0.0, 90),          # room B (south-east)
    (4, 2.4, 6.0, -90), (5, 3.55, 6.0, -90),       # room C (north-west)
    (6, 4.45, 6.0, -90), (7, 5.6, 6.0, -90),       # room D (north-east)
    (8, 0.0, 3.0, 0), (9, 8.0, 3.0, 180),          # corridor end walls
    (10, 2.0, 3.6, -90), (11, 3.0, 2.4, 90),       # corridor, facing the doors of A, C
    (12, 5.0, 2.4, 90), (13, 6.1, 3.6, -90),       # ... of D, B
)


def wall_panel(landmark_id: int, x: float, y: float, normal: float,
               layout: PanelLayout = PanelLayout(), p: float = DEFAULT_P,
               contrast: float = 1.0, centre_height: float = PANEL_CENTRE_HEIGHT,
               name: str | None = None) -> Landmark:
    """A landmark panel (``shape="panel"``) whose front face is centred on the wall point
    ``(x, y)`` (metres) and faces ``normal`` (radians, the wall's normal into the room);
    the pattern's centre hangs ``centre_height`` metres above the floor."""
    off = PANEL_DEPTH / 2 + 0.001        # 1 mm off the wall face
    cx, cy = x + off * math.cos(normal), y + off * math.sin(normal)
    base = centre_height - layout.height / 2
    if base < 0:
        raise ValueError(f"centre_height {centre_height!r} m puts the panel ({layout.height:.2f} "
                         f"m tall) below the floor; it must be >= {layout.height / 2:.3f} m")
    return Landmark(position=(cx, cy), shape="panel", extent=(layout.width, PANEL_DEPTH),
                    height=layout.height, base=base, yaw=normal - math.pi / 2,
                    color=(1.0, 1.0, 1.0, 1.0),
                    texture=panel_texture_path(landmark_id, p, layout, contrast),
                    name=name or f"selfsimilar{landmark_id}")


def _wall(a, b) -> Wall:
    """A wall of the scene on the centre line from ``a`` to ``b`` (metres)."""
    return Wall(a, b, height=WALL_HEIGHT, thickness=WALL_T, color=WALL_COLOR)


def _with_doors(x0: float, x1: float, y: float, doors: tuple[float, ...]) -> list[Wall]:
    """East-west wall segments along ``y`` from ``x0`` to ``x1`` with door openings."""
    walls, x = [], x0
    for d in sorted(doors):
        walls.append(_wall((x, y), (d - DOOR / 2, y)))
        x = d + DOOR / 2
    walls.append(_wall((x, y), (x1, y)))
    return walls


def corridors_scene() -> Scene:
    """The fixed ``corridors`` scene."""
    t = WALL_T / 2
    south, north = CORRIDOR
    walls = [
        # outer walls, their inner faces on the floor plan's border
        _wall((-t, -t), (-t, DEPTH + t)),
        _wall((WIDTH + t, -t), (WIDTH + t, DEPTH + t)),
        _wall((-t, -t), (WIDTH + t, -t)),
        _wall((-t, DEPTH + t), (WIDTH + t, DEPTH + t)),
        # room partitions (north-south) at x = 4
        _wall((WIDTH / 2, 0.0), (WIDTH / 2, south - t)),
        _wall((WIDTH / 2, north + t), (WIDTH / 2, DEPTH)),
    ]
    walls += _with_doors(0.0, WIDTH, south - t, DOORS_SOUTH)
    walls += _with_doors(0.0, WIDTH, north + t, DOORS_NORTH)
    panels, info = [], {}
    for landmark_id, x, y, normal_deg in PANELS:
        normal = math.radians(normal_deg)
        panels.append(wall_panel(landmark_id, x, y, normal))
        info[landmark_id] = (x, y, normal)
    return Scene(
        name="corridors",
        bounds=((0.0, 0.0), (WIDTH, DEPTH)),
        walls=tuple(walls),
        landmarks=tuple(panels),
        floor_color=FLOOR_COLOR,
        metadata={"landmarks": info,
                  "rooms": (((0.0, 0.0), (WIDTH / 2, south)),
                            ((WIDTH / 2, 0.0), (WIDTH, south)),
                            ((0.0, north), (WIDTH / 2, DEPTH)),
                            ((WIDTH / 2, north), (WIDTH, DEPTH)),
                            ((0.0, south), (WIDTH, north)))},
    )
