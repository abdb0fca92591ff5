"""Robot motion against the documented maxima, collisions with walls, wheel odometry."""

import numpy as np
import pytest

from homing_gym.geometry import to_frame, wrap_angle


def drive(env, action, seconds, start=(0.0, 0.0, 0.0)):
    """Place the robot at ``start``, hold ``action`` for ``seconds``; return poses and infos."""
    u = env.unwrapped
    u.sim.robot.set_pose(*start)
    u.pose = u.sim.robot.pose()
    steps = round(seconds / u.control_period)
    poses, infos = [u.pose.copy()], []
    for _ in range(steps):
        _, _, _, _, info = env.step(np.asarray(action, np.float32))
        poses.append(info["pose"])
        infos.append(info)
    return np.array(poses), infos


@pytest.fixture
def empty_env(make_env):
    from homing_gym.scenes import Scene, square_walls

    scene = Scene("empty", ((-3, -3), (3, 3)), walls=square_walls(6.0))
    env = make_env(scene=scene, panorama_shape=(16, 64))
    env.reset(seed=0)
    return env


def test_forward_one_second_moves_max_speed(empty_env):
    poses, infos = drive(empty_env, (1.0, 0.0), 1.0, start=(-1.0, 0.5, 0.3))
    travelled = np.hypot(*(poses[-1, :2] - poses[0, :2]))
    assert travelled == pytest.approx(0.3, rel=0.10)
    heading = np.arctan2(*(poses[-1, 1::-1] - poses[0, 1::-1]))
    assert abs(wrap_angle(heading - 0.3)) < 0.03
    assert not any(i["collision"] for i in infos)


@pytest.mark.parametrize("w", [1.0, -1.0, 0.5])
def test_turning_rate(empty_env, w):
    poses, _ = drive(empty_env, (0.0, w), 1.0)
    turned = np.unwrap(poses[:, 2])[-1] - poses[0, 2]
    assert turned == pytest.approx(1.5 * w, rel=0.10)
    assert np.hypot(*(poses[-1, :2] - poses[0, :2])) < 0.02


def test_out_of_range_actions_are_clipped(empty_env):
    a, _ = drive(empty_env, (5.0, 0.0), 0.5)
    b, _ = drive(empty_env, (1.0, 0.0), 0.5)
    assert np.allclose(a, b, atol=1e-6)


def test_collision_with_wall_is_detected_and_physical(empty_env):
    # wall inner face at x = 3.0; the body (radius 0.16 m) must stop at about 2.84
    poses, infos = drive(empty_env, (1.0, 0.0), 3.0, start=(2.4, 0.0, 0.0))
    assert any(i["collision"] for i in infos)
    assert not infos[0]["collision"]
    assert poses[:, 0].max() < 3.0 - 0.16 + 0.01
    assert infos[-1]["collisions"] >= 1


def test_collision_with_landmark(make_env):
    env = make_env()                          # arena: red cylinder (r 0.1075) at (0.45, 0.35)
    env.reset(seed=0)
    poses, infos = drive(env, (1.0, 0.0), 2.0, start=(-0.2, 0.35, 0.0))
    assert any(i["collision"] for i in infos)
    assert poses[:, 0].max() < 0.45 - 0.1075 - 0.16 + 0.01


@pytest.mark.parametrize("origin", ["start", "home"])
def test_odometry_without_noise_tracks_true_pose(make_env, origin):
    env = make_env(obs_keys=("panorama", "goal", "odometry"), odometry_noise=0.0,
                   panorama_shape=(16, 64), start_distance=(0.3, 0.4), odometry_origin=origin)
    obs, info = env.reset(seed=2)
    frame = info["start_pose"] if origin == "start" else info["goal_pose"]
    assert np.allclose(obs["odometry"], to_frame(frame, info["pose"]), atol=1e-5)
    for action, steps in (((1.0, 0.0), 3), ((0.0, 1.0), 10), ((0.5, -0.5), 5), ((-0.5, 0.0), 3)):
        for _ in range(steps):
            obs, _, _, _, info = env.step(np.array(action, np.float32))
    assert info["collisions"] == 0
    truth = to_frame(frame, info["pose"])
    assert np.hypot(*(obs["odometry"][:2] - truth[:2])) < 0.03
    assert abs(wrap_angle(obs["odometry"][2] - truth[2])) < 0.05


def test_default_odometry_at_reset_is_zero_whatever_home_is(make_env):
    env = make_env(obs_keys=("panorama", "odometry"), panorama_shape=(16, 64))
    start = (-0.3, -0.7, 0.3)          # clear of the cylinders
    seen = []
    for home in ((0.6, 0.5, 0.0), (-0.9, 0.8, 2.0)):
        obs, info = env.reset(seed=4, options={"start": start, "home": home})
        assert np.allclose(info["home_pose"][:2], home[:2])
        seen.append(obs["odometry"])
    assert np.array_equal(seen[0], seen[1]) and np.allclose(seen[0], 0.0)
    privileged = make_env(obs_keys=("panorama", "odometry"), panorama_shape=(16, 64),
                          odometry_origin="home")
    obs, info = privileged.reset(seed=4, options={"start": start, "home": (0.6, 0.5, 0.0)})
    assert np.allclose(obs["odometry"], to_frame(info["home_pose"], info["pose"]), atol=1e-5)
    with pytest.raises(ValueError, match="odometry_origin 'goal'"):
        make_env(odometry_origin="goal")


def test_odometry_noise_makes_estimates_drift(make_env):
    kwargs = dict(obs_keys=("panorama", "odometry"), panorama_shape=(16, 64), scene="arena")
    clean = make_env(odometry_noise=0.0, **kwargs)
    noisy = make_env(odometry_noise=0.2, **kwargs)
    for env in (clean, noisy):
        env.reset(seed=3)
    for _ in range(10):
        a, _, _, _, _ = clean.step(np.array([0.0, 1.0], np.float32))
        b, _, _, _, _ = noisy.step(np.array([0.0, 1.0], np.float32))
    assert not np.allclose(a["odometry"], b["odometry"], atol=1e-3)


def test_synchro_drive_translates_without_turning_and_its_odometry_follows(make_env):
    env = make_env(drive="synchro", obs_keys=("panorama", "odometry"), odometry_noise=0.0,
                   panorama_shape=(16, 64), scene="arena")
    obs, info = env.reset(seed=0, options={"start": (0.7, -0.1, 0.7), "home": (0.8, 0.8, 0)})
    start = info["pose"].copy()
    for action, steps in (((0.0, 1.0), 5), ((1.0, 0.0), 5), ((-0.7, -0.7), 5), ((0, 0), 3)):
        for _ in range(steps):
            obs, _, _, _, info = env.step(np.array(action, np.float32))
            assert not info["collision"]
    moved = to_frame(start, info["pose"])
    assert abs(moved[2]) < 1e-6                              # the body never turned
    # 0.3 m/s for 0.5 s each way, less the acceleration ramps; (-0.7, -0.7) goes back
    # at 0.3 m/s along the diagonal: about (0.15 - 0.074, 0.15 - 0.074) in the body frame
    assert moved[0] == pytest.approx(moved[1], abs=0.005) and 0.04 < moved[0] < 0.1
    assert np.allclose(obs["odometry"], moved, atol=1e-4)


def test_synchro_drive_refuses_what_it_cannot_do(make_env):
    with pytest.raises(ValueError, match="continuous"):
        make_env(drive="synchro", action_type="discrete")
    with pytest.raises(ValueError, match="task drives the robot itself"):
        make_env("homing_gym/LongRangeHoming-v0", drive="synchro")
    with pytest.raises(ValueError, match="unknown drive 'tank'"):
        make_env(drive="tank")
