"""The desert family: an open floor with few obstacles, a far skyline all round with peaks
above it, and obstacles the robot bumps into."""

import math

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes.base import clearances

FAMILY = "desert"
SKYLINE = ("dunes", "mesas", "mountains")
OBSTACLES = ("scrub", "rocks", "stems")


def _objects_inside(scene) -> int:
    """How many colliding objects stand inside the fence: the solids that reach down to the
    ground, those with feet less than 3 cm apart counted once (a dead bush's twigs)."""
    (xmin, ymin), (xmax, ymax) = scene.bounds
    feet: list[np.ndarray] = []
    for part in scene.meshes:
        for faces in part.solids if part.collision else ():
            corners = part.vertices[np.unique(part.faces[faces])]
            if corners[:, 2].min() > 0.02:
                continue                                  # a cactus arm
            foot = corners[corners[:, 2] < 0.05][:, :2].mean(axis=0)
            if (xmin < foot[0] < xmax and ymin < foot[1] < ymax
                    and all(math.dist(foot, f) >= 0.03 for f in feet)):
                feet.append(foot)
    return len(feet)


def test_worlds_are_fenced_squares_with_only_obstacles_colliding(world):
    for w in map(world, range(6)):
        assert w.name == "desert" and w.fence and not w.ground_plane and not w.walls
        assert 6.0 <= w.size[0] == w.size[1] <= 12.0
        assert {p.name for p in w.meshes if p.collision} <= set(OBSTACLES)
        assert not any(p.collision for p in w.meshes if p.name in SKYLINE + ("ground", "gravel"))


def test_the_floor_is_open_with_far_fewer_obstacles_than_random_nature(world, floor_grid):
    desert, nature = [], []
    for seed in range(12):
        scene = world(seed)
        desert.append(_objects_inside(scene) / (scene.size[0] * scene.size[1]))
        other = world(seed, "random_nature")
        nature.append(_objects_inside(other) / (other.size[0] * other.size[1]))
        free = clearances(scene, floor_grid(scene, shape=(40, 40), margin=0.4))
        assert np.mean(free > 0.3) > 0.75            # away from the fence
        assert regions(scene, 0.22, 0.05).max() == 1     # one open floor, no pockets
    assert np.mean(desert) < 0.5 * np.mean(nature)


def test_a_far_skyline_rings_the_world_with_peaks_above_it(world, parts_seen):
    """Seen from the floor (the skyline drawn magenta), the far features fill the view
    just above the horizon nearly all round (near objects hide some) and rise 5 degrees
    or more in some directions only."""
    for seed in range(3):
        scene = world(seed)
        for part in scene.meshes:
            if part.name in SKYLINE:
                assert np.hypot(part.vertices[:, 0], part.vertices[:, 1]).min() > 11.0
                assert np.hypot(part.vertices[:, 0], part.vertices[:, 1]).max() <= 28.1
        far, = parts_seen(scene, SKYLINE, [seed], camera_height=0.1, panorama_shape=(96, 360))
        rows = len(far) // 2                    # 0.625 degrees a row, horizon at rows
        assert far[rows - 2].mean() > 0.75                       # 1.25 degrees up
        assert 0.02 < far[rows - 8].mean() < 0.7                 # 5 degrees up


def _standing(scene, name) -> tuple[np.ndarray, float] | None:
    """The floor centre (x, y) and foot radius (metres) of the first solid of part
    ``name`` that stands on the ground inside the fence, 1 m or more from it."""
    part = next((p for p in scene.meshes if p.name == name), None)
    (xmin, ymin), (xmax, ymax) = scene.bounds
    for faces in part.solids if part else ():
        corners = part.vertices[np.unique(part.faces[faces])]
        if corners[:, 2].min() > 0.02:
            continue                                      # a cactus arm
        foot = corners[corners[:, 2] < 0.05][:, :2]
        centre = foot.mean(axis=0)
        if xmin + 1 < centre[0] < xmax - 1 and ymin + 1 < centre[1] < ymax - 1:
            return centre, float(np.linalg.norm(foot - centre, axis=1).max())
    return None


def test_robot_bumps_into_scrub_rocks_cacti_and_dead_bushes(world, drive, clear_start_facing):
    bumped = set()
    for seed in range(5):
        scene = world(seed)
        for name in OBSTACLES:
            if (standing := _standing(scene, name)) is None:
                continue
            centre, radius = standing
            start = clear_start_facing(scene, centre, 0.9,
                                       np.linspace(0, 2 * math.pi, 12, endpoint=False),
                                       f"the {name}")
            collided, pose = drive(scene, start, 45)
            assert collided and math.dist(pose[:2], centre) > 0.16, name
            bumped.add(("dead bush" if radius < 0.02 else "cactus") if name == "stems" else name)
    assert bumped == {"scrub", "rocks", "cactus", "dead bush"}
