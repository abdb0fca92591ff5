"""Fixtures of the world families' tests: a module's family drawn from a seed, parts of a
world picked or taken away, floor points and how much of them is blocked, LocalHoming-v0
in a world (the robot driven straight ahead from a pose, panoramas with the sky or some
parts in magenta), clear runs up to an obstacle and clear lines through passable parts.

What every family shares (same seed, same world; each world its own appearance; episodes
drawn 0.3-2 m apart) is tested once for all of them in ``tests/homing_gym/test_families.py``;
the tests here measure each family's own character.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from homing_gym.paths import regions
from homing_gym.scenes.base import clearances
from homing_gym.scenes.families import family
from homing_gym.scenes.mesh_part import MeshPart

#: Full speed ahead, no turn.
FORWARD = np.array([1.0, 0.0], np.float32)
MAGENTA = (1.0, 0.0, 1.0)


@pytest.fixture
def world(request):
    """``world(seed, name=None)``: the world of the test module's family (its ``FAMILY``
    name), or of family ``name``, drawn from ``np.random.default_rng(seed)``."""
    def draw(seed: int, name: str | None = None):
        return family(name or request.module.FAMILY).build(np.random.default_rng(seed))

    return draw


def _part(scene, name: str) -> MeshPart:
    return next(p for p in scene.meshes if p.name == name)


@pytest.fixture
def part():
    """``part(scene, name)``: the first mesh part of ``scene`` called ``name``."""
    return _part


@pytest.fixture
def without():
    """``without(scene, *names)``: ``scene`` less its mesh parts called any of ``names``."""
    def remove(scene, *names):
        return replace(scene, meshes=tuple(p for p in scene.meshes if p.name not in names))

    return remove


@pytest.fixture
def floor_grid():
    """``floor_grid(scene, step=0.1, shape=None, margin=0.0)``: floor points ``(N, 2)``
    over ``scene.bounds``, the centres of ``step`` metre cells or, given ``shape``
    ``(nx, ny)``, ``nx`` by ``ny`` points from edge to edge ``margin`` metres in."""
    def grid(scene, step: float = 0.1, shape=None, margin: float = 0.0) -> np.ndarray:
        (xmin, ymin), (xmax, ymax) = scene.bounds
        if shape is None:
            xs = np.arange(xmin + step / 2, xmax, step)
            ys = np.arange(ymin + step / 2, ymax, step)
        else:
            xs = np.linspace(xmin + margin, xmax - margin, shape[0])
            ys = np.linspace(ymin + margin, ymax - margin, shape[1])
        gx, gy = np.meshgrid(xs, ys)
        return np.stack([gx.ravel(), gy.ravel()], 1)

    return grid


@pytest.fixture
def blocked_share():
    """``blocked_share(scene, points)``: the share of floor ``points`` where the robot's
    centre cannot stand (clearance 0)."""
    def share(scene, points) -> float:
        return float(np.mean(clearances(scene, points) <= 0.0))

    return share


@pytest.fixture
def assert_reached_through_aisles():
    """``assert_reached_through_aisles(scene)``: the floor where the robot's centre may
    stand (0.22 m clear) is one area but for pockets under 0.3 m across, and the floor
    0.3 m clear (0.6 m aisles) holds 97 % or more of its area in one piece."""
    def check(scene) -> None:
        labels = regions(scene, 0.22, 0.05)
        sizes = np.bincount(labels.ravel())[1:]
        main = int(np.argmax(sizes)) + 1
        for label in set(range(1, len(sizes) + 1)) - {main}:
            extent = np.ptp(np.argwhere(labels == label), axis=0).max() * 0.05
            assert extent < 0.3, (scene.name, extent)
        wide = np.bincount(regions(scene, 0.3, 0.05).ravel())[1:]
        assert wide.max() >= 0.97 * wide.sum()

    return check


@pytest.fixture
def assert_solids_as_trimesh_finds():
    """``assert_solids_as_trimesh_finds(parts)``: each part's declared solids are the ones
    trimesh finds in its faces."""
    def check(parts) -> None:
        for p in parts:
            found = MeshPart(p.vertices, p.faces, p.face_colors, name=p.name).solids
            assert sorted(map(tuple, p.solids)) == sorted(map(tuple, found)), p.name

    return check


@pytest.fixture
def drive(make_env):
    """``drive(scene, start, steps)``: the robot put at ``start`` (x, y, yaw) in
    LocalHoming-v0 in ``scene`` (no step limit; one env a scene) and driven straight ahead
    ``steps`` steps; whether it collided on the way, and its last pose."""
    envs: dict[int, tuple] = {}

    def run(scene, start, steps: int):
        if id(scene) not in envs:
            envs[id(scene)] = scene, make_env(scene=scene, start_distance=(0.3, 2.0),
                                              max_episode_steps=-1)
        env = envs[id(scene)][1]
        env.reset(seed=0, options={"start": tuple(start)})
        collided = False
        for _ in range(steps):
            _, _, _, _, info = env.step(FORWARD)
            collided |= info["collision"]
        return collided, info["pose"]

    return run


@pytest.fixture
def clear_start_facing():
    """``clear_start_facing(scene, centre, gap, directions, what="it")``: a start pose
    ``gap`` metres from floor point ``centre`` facing it, from the first of
    ``directions`` (radians) that leaves 0.25 m clear."""
    def start(scene, centre, gap: float, directions, what: str = "it"):
        for a in directions:
            xy = np.asarray(centre) - gap * np.array([math.cos(a), math.sin(a)])
            if clearances(scene, [xy])[0] > 0.25:
                return (*xy, a)
        raise AssertionError(f"no clear start facing {what}")

    return start


@pytest.fixture
def line_through():
    """``line_through(scene, points, length=1.2, turn=0.0, what="it")``: a start pose
    0.6 m short of the first of floor ``points`` (passable parts) from which a straight
    line of ``length`` metres through it, heading towards the middle of the world turned
    by ``turn`` radians, stays 0.3 m clear of obstacles."""
    def start(scene, points, length: float = 1.2, turn: float = 0.0, what: str = "it"):
        for point in points:
            a = math.atan2(-point[1], -point[0]) + turn
            heading = np.array([math.cos(a), math.sin(a)])
            xy = point - 0.6 * heading
            line = xy + np.linspace(0, length, round(length / 0.05) + 1)[:, None] * heading
            if clearances(scene, line).min() > 0.3:
                return (*xy, a)
        raise AssertionError(f"no clear line through {what}")

    return start


@pytest.fixture
def bump_into_a_side(drive):
    """``bump_into_a_side(scene, rects, run)``: the robot driven 40 steps at the middle of
    a side of the first floor rectangle of ``rects`` (x0, y0, x1, y1) with a clear run up
    to it (0.2 to ``run`` metres out, 0.16 m clear) must collide; how far (metres) its
    centre stopped outside the rectangle."""
    def bump(scene, rects, run: float) -> float:
        for x0, y0, x1, y1 in rects:
            for edge, yaw in ((((x0 + x1) / 2, y0), math.pi / 2),
                              (((x0 + x1) / 2, y1), -math.pi / 2),
                              ((x0, (y0 + y1) / 2), 0.0), ((x1, (y0 + y1) / 2), math.pi)):
                ahead = np.array([math.cos(yaw), math.sin(yaw)])
                line = np.array(edge) - np.linspace(0.2, run, round((run - 0.2) / 0.05) + 1
                                                    )[:, None] * ahead
                if clearances(scene, line).min() > 0.16:
                    collided, (x, y, _) = drive(scene, (*line[-1], yaw), 40)
                    assert collided
                    return max(x0 - x, x - x1, y0 - y, y - y1)
        raise AssertionError("no rectangle with a clear side")

    return bump


@pytest.fixture
def panoramas(make_env):
    """``panoramas(scene, seeds, **env_kwargs)``: the panorama (RGB as ints) at the start of
    the episode reset with each of ``seeds`` in LocalHoming-v0 in ``scene`` (episodes
    0.3-2 m; ``env_kwargs`` e.g. ``camera_height``, ``panorama_shape``)."""
    def render(scene, seeds, **env_kwargs) -> list[np.ndarray]:
        env = make_env(scene=scene, start_distance=(0.3, 2.0), **env_kwargs)
        return [env.reset(seed=seed)[0]["panorama"].astype(int) for seed in seeds]

    return render


@pytest.fixture
def sky_seen(panoramas):
    """``sky_seen(scene, seed)``: where the sky shows (a bool mask) in the ``(48, 256)``
    panorama at the start of the episode reset with ``seed``, the camera 0.2 m up under a
    plain magenta sky: 1.25 degrees a row from 30 degrees up (the horizon below row 24)."""
    def mask(scene, seed: int) -> np.ndarray:
        plain = replace(scene, appearance=replace(scene.appearance, sky_zenith=None))
        pano, = panoramas(plain, [seed], camera_height=0.2, sky_color=MAGENTA,
                          panorama_shape=(48, 256))
        return (pano[..., 0] > 200) & (pano[..., 1] < 40) & (pano[..., 2] > 200)

    return mask


@pytest.fixture
def parts_seen(panoramas):
    """``parts_seen(scene, names, seeds, **env_kwargs)``: where the mesh parts called any
    of ``names``, drawn magenta, show (a bool mask, shading allowed) in the panorama at the
    start of the episode reset with each of ``seeds``."""
    def masks(scene, names, seeds, **env_kwargs) -> list[np.ndarray]:
        magenta = tuple(MeshPart(p.vertices, p.faces, np.tile(MAGENTA, (len(p.faces), 1)),
                                 collision=False, name=p.name, solid_faces=())
                        if p.name in names else p for p in scene.meshes)
        return [(pano[..., 1] < 0.3 * pano[..., 0]) & (pano[..., 1] < 0.3 * pano[..., 2])
                for pano in panoramas(replace(scene, meshes=magenta), seeds, **env_kwargs)]

    return masks
