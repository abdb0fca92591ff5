"""The desert family: worlds reproducible from the seed and distinct across seeds, an open
floor with few obstacles, a far skyline all round with peaks above it, obstacles the
robot bumps into, and LocalHoming episodes in every world."""

import math
from dataclasses import replace

import numpy as np

from homing_gym.paths import regions
from homing_gym.scenes import SceneFactory
from homing_gym.scenes.base import clearances
from homing_gym.scenes.families.desert import desert_scene
from homing_gym.scenes.mesh_part import MeshPart
from homing_gym.scenes.random_nature import random_nature_scene

FORWARD = np.array([1.0, 0.0], np.float32)
SKYLINE = ("dunes", "mesas", "mountains")
OBSTACLES = ("scrub", "rocks", "stems")


def _world(seed):
    return desert_scene(np.random.default_rng(seed))


def _signature(scene) -> tuple:
    meshes = tuple((p.name, p.vertices.round(9).tobytes(), p.face_colors.round(9).tobytes())
                   for p in scene.meshes)
    return scene.bounds, scene.sky_color, scene.appearance, meshes


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


def test_worlds_are_reproducible_and_distinct():
    assert _signature(_world(7)) == _signature(_world(7))
    worlds = [_world(seed) for seed in range(6)]
    assert len({_signature(w) for w in worlds}) == 6
    assert len({w.bounds for w in worlds}) == 6
    for w in worlds:
        assert w.name == "desert" and w.fence and not w.ground_plane and not w.walls
        assert 6.0 <= w.size[0] == w.size[1] <= 12.0
        assert {p.name for p in w.meshes if p.collision} <= set(OBSTACLES)
        assert not any(p.collision for p in w.meshes if p.name in SKYLINE + ("ground", "gravel"))


def test_the_floor_is_open_with_far_fewer_obstacles_than_random_nature():
    desert, nature = [], []
    for seed in range(12):
        scene = _world(seed)
        desert.append(_objects_inside(scene) / (scene.size[0] * scene.size[1]))
        other = random_nature_scene(np.random.default_rng(seed))
        nature.append(_objects_inside(other) / (other.size[0] * other.size[1]))
        (xmin, ymin), (xmax, ymax) = scene.bounds
        gx, gy = np.meshgrid(np.linspace(xmin + 0.4, xmax - 0.4, 40),
                             np.linspace(ymin + 0.4, ymax - 0.4, 40))
        free = clearances(scene, np.stack([gx.ravel(), gy.ravel()], 1))
        assert np.mean(free > 0.3) > 0.75            # away from the fence
    assert np.mean(desert) < 0.5 * np.mean(nature)


def test_a_far_skyline_rings_the_world_with_peaks_above_it(make_env):
    """Seen from the floor (the skyline drawn magenta), the far features fill the view
    just above the horizon nearly all round (near objects hide some) and rise 5 degrees
    or more in some directions only."""
    for seed in range(3):
        scene = _world(seed)
        for part in scene.meshes:
            if part.name in SKYLINE:
                assert np.hypot(part.vertices[:, 0], part.vertices[:, 1]).min() > 11.0
                assert np.hypot(part.vertices[:, 0], part.vertices[:, 1]).max() <= 28.1
        magenta = tuple(MeshPart(p.vertices, p.faces, np.tile([1.0, 0.0, 1.0], (len(p.faces), 1)),
                                 collision=False, name=p.name, solid_faces=())
                        if p.name in SKYLINE else p for p in scene.meshes)
        env = make_env(scene=replace(scene, meshes=magenta), start_distance=(0.3, 2.0),
                       camera_height=0.1, panorama_shape=(96, 360))
        obs, _ = env.reset(seed=seed)
        pano = obs["panorama"].astype(int)
        far = (pano[..., 1] < 0.3 * pano[..., 0]) & (pano[..., 1] < 0.3 * pano[..., 2])
        rows = len(pano) // 2                   # 0.625 degrees a row, horizon at rows
        assert far[rows - 2].mean() > 0.75                       # 1.25 degrees up
        assert 0.02 < far[rows - 8].mean() < 0.7                 # 5 degrees up


def test_local_homing_episodes_are_drawn_in_every_world(make_env):
    env = make_env(scene=SceneFactory(build=desert_scene, randomised=True),
                   start_distance=(0.3, 2.0))
    for seed in range(5):
        _, info = env.reset(seed=seed)
        assert 0.3 <= math.dist(info["home_pose"][:2], info["start_pose"][:2]) <= 2.0
        assert env.unwrapped.scene.name == "desert"
        assert regions(env.unwrapped.scene, 0.22, 0.05).max() == 1      # one open floor


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


def test_robot_bumps_into_scrub_rocks_cacti_and_dead_bushes(make_env):
    bumped = set()
    for seed in range(5):
        scene = _world(seed)
        env = make_env(scene=scene, start_distance=(0.3, 2.0), max_episode_steps=-1)
        for name in OBSTACLES:
            if (standing := _standing(scene, name)) is None:
                continue
            centre, radius = standing
            for a in np.linspace(0, 2 * math.pi, 12, endpoint=False):   # a clear start facing it
                start = centre - 0.9 * np.array([math.cos(a), math.sin(a)])
                if clearances(scene, [start])[0] > 0.25:
                    break
            else:
                raise AssertionError(f"no clear start facing the {name}")
            env.reset(seed=0, options={"start": (*start, a)})
            collisions = 0
            for _ in range(45):
                _, _, _, _, info = env.step(FORWARD)
                collisions += info["collision"]
            assert collisions > 0 and math.dist(info["pose"][:2], centre) > 0.16, name
            bumped.add(("dead bush" if radius < 0.02 else "cactus") if name == "stems" else name)
    assert bumped == {"scrub", "rocks", "cactus", "dead bush"}
