"""Bounds and types of the env arguments that only some env ids take (the fuzz in
test_fuzz.py draws an env id at random for each of its cases): each bad value is refused
at ``gym.make`` with a ``ValueError`` naming the argument and what is allowed, before
anything big is built; the largest allowed route is checked and reset quickly."""

import gymnasium as gym
import numpy as np
import pytest

import homing_gym  # noqa: F401
from homing_gym.scenes.base import Scene
from homing_gym.scenes.mesh_example import write_example_room
from homing_gym.scenes.mesh_scene import _cached_scene
from homing_gym.tasks.route_file import MAX_ROUTE_POINTS
from homing_gym.tasks.work_locations import WorkLocationsTask

SMALL = {"panorama_shape": (16, 64)}
ROUTE, WORK, LONG = ("homing_gym/RouteFollowing-v0", "homing_gym/WorkLocations-v0",
                     "homing_gym/LongRangeHoming-v0")


def _meander(n: int, step: float = 0.06) -> list[tuple[float, float]]:
    """``n`` points ``step`` metres apart in lanes along the hallway's free middle."""
    lanes, xs = (-0.2, -0.1, 0.0, 0.1, 0.2), [1.0 + step * i for i in range(101)]
    points: list[tuple[float, float]] = []
    lane = 0
    while len(points) < n:
        points += [(x, lanes[lane % 5]) for x in (xs if lane % 2 == 0 else xs[::-1])]
        lane += 1
    return points[:n]


@pytest.mark.parametrize("env_id, kwargs, words", [
    (ROUTE, {"n_targets": 10**9}, ["n_targets", "9,999", "10000 points"]),
    (ROUTE, {"n_targets": True}, ["n_targets", "integer"]),
    (ROUTE, {"n_targets": 40}, ["40 targets", "at most 22 fit"]),
    (ROUTE, {"spacing": 1e-9}, ["spacing", "[0.05, 100] metres"]),
    (ROUTE, {"spacing": float("nan")}, ["spacing", "[0.05, 100] metres"]),
    (ROUTE, {"success_radius": 1e6}, ["success_radius", "(0, 2]"]),
    (ROUTE, {"success_radius": 0.5}, ["success_radius 0.5 m", "first target", "0.305 m"]),
    (ROUTE, {"route": _meander(MAX_ROUTE_POINTS + 1)}, ["route", "10001 points",
                                                         "at most 10000"]),
    (ROUTE, {"start_jitter": (0.05, 1e9)}, ["start_jitter", "[0, pi]"]),
    (ROUTE, {"start_jitter": (True, 0.1)}, ["start_jitter", "two numbers"]),
    (ROUTE, {"start_jitter": ("a", 0.1)}, ["start_jitter", "two numbers"]),
    (WORK, {"success_radius": 1e6}, ["success_radius", "(0, 2]"]),
    (WORK, {"teach_levels": True}, ["teach_levels", "integer in [1, 4]"]),
    (WORK, {"max_points": True}, ["max_points", "integer in [2, 10]"]),
    (WORK, {"template_size": 16}, ["template_size", "odd"]),
    (WORK, {"place_spacing": "0.5"}, ["place_spacing", "[0.05, 2] metres"]),
    (WORK, {"start_jitter": (0.05, -1)}, ["start_jitter", "[0, pi]"]),
    (LONG, {"success_radius": 1e6}, ["success_radius", "(0, 2]"]),
    (LONG, {"physics_substeps": True}, ["physics_substeps", "integer in [1, 1,000]"]),
    ("homing_gym/LocalHoming-v0", {"n_views": 6.0, "renderer": "tiny"}, ["n_views"]),
])
def test_bad_task_arguments_are_refused_by_name(env_id, kwargs, words):
    with pytest.raises(ValueError) as err:
        gym.make(env_id, **kwargs, **SMALL)
    for word in words:
        assert word in str(err.value), str(err.value)


def test_work_locations_closer_than_the_success_radius_are_refused():
    scene = Scene(name="two places", bounds=((-2.0, -2.0), (2.0, 2.0)), metadata={
        "work_locations": {"desk": (0.0, 0.0, 0.0), "shelf": (0.5, 0.0, 0.0)},
        "paths": {("desk", "shelf"): np.array([[0.0, 0.0], [0.5, 0.0]])}})
    WorkLocationsTask((64, 512), success_radius=0.45).check_scene(scene)
    with pytest.raises(ValueError, match=r"success_radius 0.6 m: the work locations 'desk' "
                                         r"and 'shelf' are 0.500 m apart"):
        WorkLocationsTask((64, 512), success_radius=0.6).check_scene(scene)


def test_the_targets_said_to_fit_do_fit():
    env = gym.make(ROUTE, n_targets=22, **SMALL)
    _, info = env.reset(seed=0)
    assert len(env.unwrapped.episode.goals) == 22
    env.close()


def test_the_largest_route_is_followed_target_by_target():
    """A route of the most points allowed is accepted, and each target's snapshot is the
    panorama at that target (taken when the target becomes current)."""
    env = gym.make(ROUTE, route=_meander(MAX_ROUTE_POINTS), success_radius=0.05, **SMALL)
    obs, _ = env.reset(seed=0)
    inner = env.unwrapped
    assert len(inner.episode.goals) == MAX_ROUTE_POINTS - 1
    for k in range(3):
        assert np.array_equal(obs["goal"], inner.render_panorama(inner.goal_pose))
        inner.advance_goal()
        obs = inner.observation()
        assert inner.goal_index == k + 1
    env.close()


@pytest.mark.parametrize("query, words", [
    ("offset=1e9,0,0", ["reaches 1e+09 m", "within 10000 m", "offset"]),
    ("scale=1e6", ["within 10000 m", "scale"]),
    ("bounds=20000,0,20010,10", ["bounds", "10000 m from the origin"]),
    ("scale=1&scale=2", ["'scale' is given twice"]),
    ("&&", ["empty option", "mesh:PATH?option=value&option=value"]),
])
def test_mesh_worlds_far_from_the_origin_or_mistyped_are_refused(tmp_path, query, words):
    path = tmp_path / "room.obj"
    write_example_room(path)
    try:
        with pytest.raises(ValueError) as err:
            gym.make("homing_gym/LocalHoming-v0", scene=f"mesh:{path}?{query}", **SMALL)
    finally:
        _cached_scene.cache_clear()
    for word in words:
        assert word in str(err.value), str(err.value)


def test_a_folder_given_as_a_mesh_is_called_a_folder(tmp_path):
    with pytest.raises(ValueError, match="is a directory, not a mesh file"):
        gym.make("homing_gym/LocalHoming-v0", scene=f"mesh:{tmp_path}", **SMALL)


def test_a_boolean_seed_is_refused():
    env = gym.make("homing_gym/LocalHoming-v0", **SMALL)
    with pytest.raises(ValueError, match="seed must be an integer >= 0 or None, got True"):
        env.reset(seed=True)
    env.close()
