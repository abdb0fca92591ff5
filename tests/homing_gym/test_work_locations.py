"""WorkLocations-v0: the house, teaching, daily changes, argument checks."""

import math

import numpy as np
import pytest

from homing_gym.render.panorama import column_bearing
from homing_gym.scenes.base import clearance
from homing_gym.scenes.daily_changes import daily_changes
from homing_gym.scenes.house import house_scene
from homing_gym.teaching import path_places
from homing_gym.vision import low_resolution

ENV_ID = "homing_gym/WorkLocations-v0"


def test_house_paths_are_clear_and_connect_the_work_locations():
    scene = house_scene()
    meta = scene.metadata
    assert meta["home"] in meta["work_locations"]
    names = set(meta["work_locations"])
    assert set(meta["paths"]) == {(a, b) for a in names for b in names if a != b}
    for (a, b), points in meta["paths"].items():
        assert points[0] == meta["work_locations"][a][:2]
        assert points[-1] == meta["work_locations"][b][:2]
        for pose in path_places(points, 0.05):
            assert clearance(scene, pose[:2]) > 0.3, ((a, b), pose)


def test_path_places_every_spacing_with_corners_and_end():
    places = path_places([(0, 0), (1.0, 0), (1.0, 1.0)], 0.47)
    assert np.allclose(places[:, :2], [(0, 0), (0.47, 0), (1.0, 0), (1.0, 0.41), (1.0, 0.88),
                                       (1.0, 1.0)])
    assert np.allclose(places[:, 2], [0, 0, math.pi / 2, math.pi / 2, math.pi / 2,
                                      math.pi / 2])
    with pytest.raises(ValueError, match="two"):
        path_places([(0, 0)])


def test_daily_changes_move_remove_add_small_objects_only_and_keep_paths_free():
    scene = house_scene()
    small = set(scene.metadata["small_objects"])
    changed = daily_changes(scene, np.random.default_rng(3), 1.0)
    fixed = lambda s: [lm for lm in s.landmarks if not lm.name.startswith("small_")]  # noqa
    assert fixed(changed) == fixed(scene)
    before = {lm.name: lm for lm in scene.landmarks if lm.name in small}
    after = {lm.name: lm for lm in changed.landmarks if lm.name.startswith("small_")}
    assert after != before and any(n.startswith("small_added") for n in after)
    for (a, b), points in scene.metadata["paths"].items():
        for pose in path_places(points, 0.05):
            assert clearance(changed, pose[:2]) > 0.3
    assert daily_changes(scene, np.random.default_rng(3), 0.0) is scene
    with pytest.raises(ValueError, match="strength"):
        daily_changes(scene, np.random.default_rng(0), 1.5)


def test_taught_path_panoramas_are_centred_on_the_direction_of_travel(make_env):
    env = make_env(ENV_ID, start_location="home", goal_location="kitchen")
    obs, info = env.reset(seed=0)
    u = env.unwrapped
    k = int(obs["path_count"])
    places = info["places"]
    assert k == len(places) and np.allclose(places[-1][:2], info["goal_pose"][:2])
    assert not obs["path_panoramas"][k:].any() and obs["path_panoramas"][k - 1].any()
    # the stored image of place 3 is the low-resolution panorama facing the travel direction
    view = low_resolution(u.render_panorama(places[3]), u.task.levels)
    assert np.abs(view.astype(int) - obs["path_panoramas"][3]).mean() < 2
    assert obs["path_panoramas"].shape[1:] == (16, 128)


def test_feature_map_templates_and_points_agree(make_env):
    env = make_env(ENV_ID, goal_location="bedroom")
    obs, info = env.reset(seed=1)
    n = int(obs["map_count"])
    assert n >= 3
    pose = obs["map_pose"]
    assert np.allclose(pose, info["goal_pose"], atol=1e-6)
    H, W = env.unwrapped.camera.config.panorama_shape
    for (col, row), point in zip(obs["map_template_xy"][:n], obs["map_points"][:n]):
        bearing = column_bearing(col * 4, W)
        true = math.atan2(point[1] - pose[1], point[0] - pose[0]) - pose[2]
        assert abs(math.remainder(bearing - true, 2 * math.pi)) < 1e-4
        assert 0 < row < H / 4
    assert not obs["map_templates"][n:].any()


def test_reset_is_reproducible_and_daily_changes_leave_teaching_unchanged(make_env):
    plain = make_env(ENV_ID, goal_location="kitchen")
    changed = make_env(ENV_ID, goal_location="kitchen", daily_changes=1.0)
    a, _ = plain.reset(seed=4)
    b, _ = changed.reset(seed=4)
    c, _ = changed.reset(seed=4)
    for key in ("path_panoramas", "map_templates", "map_panorama", "map_points"):
        assert np.array_equal(a[key], b[key]), key
    assert all(np.array_equal(b[k], c[k]) for k in b)
    assert changed.unwrapped.scene != plain.unwrapped.scene


@pytest.mark.parametrize("kwargs, match", [
    ({"goal_location": "garage"}, "goal_location"),
    ({"start_location": "home", "goal_location": "home"}, "different"),
    ({"daily_changes": 2.0}, "daily_changes"),
    ({"teach_levels": 0}, "teach_levels"),
    ({"template_size": 16}, "template_size"),
    ({"scene": "arena"}, "work_locations"),
])
def test_bad_arguments_raise_clear_errors(make_env, kwargs, match):
    with pytest.raises(ValueError, match=match):
        make_env(ENV_ID, **kwargs)


def test_home_option_is_refused(make_env):
    env = make_env(ENV_ID, goal_location="kitchen")
    with pytest.raises(ValueError, match="home"):
        env.reset(seed=0, options={"home": (1.0, 1.0, 0.0)})
