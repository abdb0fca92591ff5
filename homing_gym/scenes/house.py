"""``house``: an ordinary home with work locations and taught travel paths (the setting of
Shiraishi & Sawasaki, "multi-resolution image matching", §2: a robot working in an
unoccupied house, limited to "work locations" and the paths that connect them).

An 8 x 6 m floor (x in [0, 8], y in [0, 6]) with 2.4 m walls: a living room in the west
(4.5 x 6 m) and, east of it, a bedroom (south, 3.5 x 3 m) and a kitchen (north, 3.5 x
3 m), each reached from the living room through a 0.9 m doorway in the wall x = 4.5 (at
y = 1.5 and y = 4.5). Furniture (sofa, armchair, coffee table, TV, bookshelf, plant;
counter, fridge, kitchen table; bed, wardrobe, desk), pictures on the walls (textured
panels, some repeated: similar-looking characteristic points, problem (b-2) of §2) and
small everyday objects (cushion, ball, basket, shoe box, bag, shoes, books: what daily
life moves around, problem (b-1); see :mod:`homing_gym.scenes.daily_changes`). As in
the ``hallway`` scene, pictures hang low (centres 0.6-0.75 m) so that the camera, 0.30 m
above the floor with a +-30 degree vertical field of view, sees them.

``scene.metadata``:

* ``"work_locations"``: ``{name: (x, y, yaw)}`` (metres, radians): ``home`` (the robot's
  dock, facing the west wall), ``kitchen`` and ``bedroom`` (facing the counter and the
  wardrobe, each 1.2-1.5 m from the wall ahead, like the paper's goal "1.5 meters from
  the wall", §4(1));
* ``"home"``: the name of the home location;
* ``"paths"``: ``{(from, to): ((x, y), ...)}``: the travel path of every ordered pair
  of work locations, a polyline through the doorways from one location to the other
  (the reverse of a path is the path back);
* ``"feature_points"``: ``{name: (x, y, z)}``: candidate characteristic points for the
  multiresolution feature image maps (§3(2)), the centre of each picture's face
  (indoor coordinates, metres);
* ``"small_objects"``: the names of the landmarks that daily changes may move or remove;
* ``"rooms"``: the free rectangles of the floor plan (where daily changes may add objects).
"""

from __future__ import annotations

import math

from homing_gym.scenes.base import Landmark, Scene, Wall

WIDTH, DEPTH, HEIGHT = 8.0, 6.0, 2.4
WALL_T = 0.1
#: x of the wall between the living room and the two east rooms; y of the wall between
#: bedroom and kitchen.
PARTITION_X, PARTITION_Y = 4.5, 3.0
DOOR = 0.9
DOORS_Y = (1.5, 4.5)
PICTURE_DEPTH = 0.02

WORK_LOCATIONS = {"home": (1.0, 3.0, math.pi), "kitchen": (6.5, 4.5, 0.0),
                  "bedroom": (6.5, 1.5, 0.0)}
HOME = "home"
#: Inner corners of the routes through the living room (metres).
_VIA = {"home": ((3.5, 3.0),), "kitchen": ((3.5, 4.5),), "bedroom": ((3.5, 1.5),)}

FABRIC = (0.35, 0.4, 0.55, 1.0)
WHITE = (1.0, 1.0, 1.0, 1.0)


def _route(a: str, b: str) -> tuple[tuple[float, float], ...]:
    """The polyline from work location ``a`` to ``b``: out of ``a``'s room to its corner
    in the living room, along x = 3.5, into ``b``'s room."""
    start, end = WORK_LOCATIONS[a][:2], WORK_LOCATIONS[b][:2]
    return (start, *_VIA[a], *_VIA[b], end)


PATHS = {(a, b): _route(a, b) for a in WORK_LOCATIONS for b in WORK_LOCATIONS if a != b}

#: Pictures: (name, x, y on the wall (or furniture) face, normal into the room in
#: degrees, texture, width, height, centre height), metres.
PICTURES = (
    ("picture_west_n", 0.0, 3.9, 0, "poster_a", 0.6, 0.45, 0.7),
    ("picture_west_s", 0.0, 2.1, 0, "poster_b", 0.5, 0.4, 0.65),
    ("picture_living_n", 2.9, 6.0, -90, "checker_green", 0.6, 0.45, 0.75),
    ("picture_living_s", 3.3, 0.0, 90, "stripes_warm", 0.6, 0.45, 0.7),
    ("picture_living_e", 4.45, 3.6, 180, "poster_b", 0.5, 0.4, 0.65),
    ("picture_kitchen_n", 6.0, 6.0, -90, "poster_a", 0.6, 0.45, 0.7),
    ("picture_kitchen_n2", 4.9, 6.0, -90, "stripes_warm", 0.5, 0.4, 0.7),
    ("picture_kitchen_w", 4.55, 5.5, 0, "poster_b", 0.5, 0.4, 0.65),
    ("picture_kitchen_s", 6.7, 3.05, 90, "checker_dark", 0.5, 0.4, 0.7),
    ("picture_bedroom_s", 6.9, 0.0, 90, "poster_b", 0.6, 0.45, 0.7),
    ("picture_bedroom_e", 8.0, 2.7, 180, "checker_green", 0.4, 0.35, 0.9),
    ("picture_bedroom_w", 4.55, 0.5, 0, "stripes_cool", 0.5, 0.4, 0.65),
    ("picture_bedroom_n", 7.3, 2.95, -90, "poster_a", 0.5, 0.4, 0.75),
    # pictures stuck on furniture: the fridge, a cupboard door, the wardrobe, the desk
    ("picture_fridge", 7.25, 5.6, 180, "checker_green", 0.3, 0.3, 0.6),
    ("picture_cupboard", 7.4, 3.95, 180, "stripes_cool", 0.4, 0.3, 0.5),
    ("picture_wardrobe", 7.4, 1.05, 180, "stripes_warm", 0.35, 0.3, 0.5),
    ("picture_desk", 5.5, 0.55, 90, "checker_dark", 0.4, 0.3, 0.45),
)


def _box(name: str, x: float, y: float, width: float, depth: float, height: float,
         base: float = 0.0, yaw: float = 0.0, color=WHITE, texture: str | None = None
         ) -> Landmark:
    return Landmark(position=(x, y), shape="box", extent=(width, depth), height=height,
                    base=base, yaw=yaw, color=color, texture=texture, name=name)


def picture(name: str, x: float, y: float, normal: float, texture: str, width: float,
            height: float, centre_height: float) -> Landmark:
    """A picture (``shape="panel"``) whose face is centred on the wall point ``(x, y)``
    (metres) ``centre_height`` metres above the floor, facing ``normal`` (radians)."""
    off = PICTURE_DEPTH / 2 + 0.001
    return Landmark(position=(x + off * math.cos(normal), y + off * math.sin(normal)),
                    shape="panel", extent=(width, PICTURE_DEPTH), height=height,
                    base=centre_height - height / 2, yaw=normal - math.pi / 2, color=WHITE,
                    texture=texture, name=name)


def _wall(a, b, texture: str) -> Wall:
    return Wall(a, b, height=HEIGHT, thickness=WALL_T, texture=texture)


def _walls() -> tuple[Wall, ...]:
    t = WALL_T / 2
    px, py = PARTITION_X, PARTITION_Y
    (d1, d2), h = DOORS_Y, DOOR / 2
    return (
        # outer walls, inner faces on the floor plan's border; one texture per room
        _wall((-t, -t), (-t, DEPTH + t), "concrete"),
        _wall((-t, -t), (px, -t), "concrete"),
        _wall((-t, DEPTH + t), (px, DEPTH + t), "concrete"),
        _wall((px, -t), (WIDTH + t, -t), "stripes_warm"),
        _wall((WIDTH + t, -t), (WIDTH + t, py), "stripes_warm"),
        _wall((WIDTH + t, py), (WIDTH + t, DEPTH + t), "bricks_grey"),
        _wall((px, DEPTH + t), (WIDTH + t, DEPTH + t), "bricks_grey"),
        # the partition with its two doorways, and the bedroom-kitchen wall
        _wall((px, 0.0), (px, d1 - h), "concrete"),
        _wall((px, d1 + h), (px, d2 - h), "concrete"),
        _wall((px, d2 + h), (px, DEPTH), "concrete"),
        _wall((px + t, py), (WIDTH, py), "bricks_red"),
    )


def _furniture() -> tuple[Landmark, ...]:
    return (
        # living room
        _box("dock", 0.12, 3.0, 0.2, 0.35, 0.12, color=(0.15, 0.15, 0.17, 1.0)),
        _box("sofa", 1.6, 5.5, 2.0, 0.8, 0.45, color=FABRIC),
        _box("sofa_back", 1.6, 5.85, 2.0, 0.2, 0.35, base=0.45, color=FABRIC),
        _box("coffee_table", 1.6, 4.4, 1.0, 0.5, 0.4, texture="wood_dark"),
        _box("tv_stand", 1.8, 0.25, 1.4, 0.45, 0.45, texture="wood_dark"),
        _box("tv", 1.8, 0.2, 1.0, 0.06, 0.6, base=0.45, color=(0.05, 0.05, 0.06, 1.0)),
        _box("bookshelf", 0.2, 1.0, 1.0, 0.35, 1.8, yaw=math.pi / 2, texture="wood_light"),
        _box("armchair", 3.3, 5.4, 0.8, 0.8, 0.45, color=(0.6, 0.25, 0.2, 1.0)),
        Landmark((4.1, 5.6), radius=0.18, height=0.35, color=(0.45, 0.3, 0.2, 1.0),
                 name="plant_pot"),
        Landmark((4.1, 5.6), radius=0.25, height=0.45, base=0.35,
                 color=(0.15, 0.5, 0.2, 1.0), name="plant"),
        # kitchen
        _box("counter", 7.7, 4.5, 2.2, 0.6, 0.9, yaw=math.pi / 2, texture="wood_light"),
        _box("fridge", 7.6, 5.6, 0.7, 0.7, 1.8, color=(0.92, 0.93, 0.95, 1.0)),
        _box("kitchen_table", 5.7, 3.6, 1.0, 0.6, 0.75, texture="wood_dark"),
        # bedroom
        _box("bed", 5.6, 2.45, 1.8, 1.0, 0.5, color=(0.85, 0.8, 0.7, 1.0)),
        _box("wardrobe", 7.7, 1.4, 1.2, 0.6, 1.9, yaw=math.pi / 2, texture="wood_dark"),
        _box("desk", 5.5, 0.3, 1.0, 0.5, 0.75, texture="wood_light"),
    )


#: Small everyday objects that daily changes move, remove or add (problem (b-1)).
def _small_objects() -> tuple[Landmark, ...]:
    return (
        _box("small_cushion", 2.6, 5.0, 0.4, 0.4, 0.12, yaw=0.3, color=(0.85, 0.6, 0.2, 1.0)),
        Landmark((2.6, 1.3), radius=0.08, height=0.16, color=(0.9, 0.15, 0.15, 1.0),
                 name="small_ball"),
        Landmark((0.6, 5.0), radius=0.2, height=0.35, color=(0.75, 0.7, 0.55, 1.0),
                 name="small_basket"),
        _box("small_shoebox", 4.0, 0.5, 0.35, 0.22, 0.13, yaw=0.2,
             color=(0.3, 0.45, 0.7, 1.0)),
        _box("small_bag", 5.2, 5.5, 0.4, 0.2, 0.3, color=(0.4, 0.25, 0.15, 1.0)),
        _box("small_shoes", 7.0, 0.5, 0.3, 0.25, 0.1, color=(0.1, 0.1, 0.1, 1.0)),
        _box("small_books", 2.1, 4.4, 0.3, 0.22, 0.12, base=0.4, color=(0.7, 0.2, 0.3, 1.0)),
    )


def house_scene() -> Scene:
    """The fixed ``house`` scene."""
    pictures, points = [], {}
    for name, x, y, normal_deg, texture, width, height, centre in PICTURES:
        normal = math.radians(normal_deg)
        pictures.append(picture(name, x, y, normal, texture, width, height, centre))
        off = PICTURE_DEPTH + 0.001
        points[name] = (x + off * math.cos(normal), y + off * math.sin(normal), centre)
    small = _small_objects()
    return Scene(
        name="house",
        bounds=((0.0, 0.0), (WIDTH, DEPTH)),
        walls=_walls(),
        landmarks=_furniture() + tuple(pictures) + small,
        floor_color=WHITE,
        floor_texture="wood_light",
        metadata={"work_locations": dict(WORK_LOCATIONS), "home": HOME, "paths": dict(PATHS),
                  "feature_points": points,
                  "small_objects": tuple(lm.name for lm in small),
                  "rooms": (((0.0, 0.0), (PARTITION_X, DEPTH)),
                            ((PARTITION_X, 0.0), (WIDTH, PARTITION_Y)),
                            ((PARTITION_X, PARTITION_Y), (WIDTH, DEPTH)))},
    )
