"""``bearing-longrange`` (Bekris, Argyros & Kavraki §3, Fig. 5): milestones from the
features' life cycles, the median realignment, and homing from pixels in
LongRangeHoming-v0."""

import math

import numpy as np
import pytest

import homing_baselines
from homing_baselines.bearing_longrange import (MemoryFrame, birth_frames, choose_milestones,
                                                median_offset)
from homing_baselines.klt import KLTConfig
from homing_gym.geometry import wrap_angle
from homing_train.harness.evaluate import run_episode


def test_milestones_are_the_earliest_frames_sharing_enough_features():
    # Fig. 5 in small: life cycles 0: frames 0-2, 1: 0-4, 2: 1-6, 3: 2-6, 4: 3-6, 5: 5-6
    alive = {0: (0, 2), 1: (0, 4), 2: (1, 6), 3: (2, 6), 4: (3, 6), 5: (5, 6)}
    frames = [np.array([i for i, (b, e) in alive.items() if b <= t <= e]) for t in range(7)]
    assert birth_frames(frames) == {i: b for i, (b, _) in alive.items()}
    # from G = 6: features 2, 3, 4 (born 1, 2, 3) are shared back to frame 3; frame 3
    # holds 1-4, of which 1, 2, 3 reach back to frame 2; frame 2 holds 0-3, of which 0,
    # 1, 2 reach back to frame 1; frame 1 shares only 0 and 1 with frame 0.
    assert choose_milestones(frames, 3) == [3, 2, 1, 0]
    assert choose_milestones(frames, 2) == [2, 0]
    # asking for more than a frame holds: step back one frame at a time
    assert choose_milestones(frames, 5) == [5, 4, 3, 2, 1, 0]
    assert choose_milestones(frames[:1], 3) == []
    with pytest.raises(ValueError, match="empty"):
        choose_milestones([], 3)


def test_median_offset_is_robust_and_does_not_split_at_pi():
    # -0.02, +0.01, +0.03 around pi: the median is pi + 0.01 (a plain median of the
    # wrapped values would give -pi + 0.03)
    offsets = np.array([math.pi - 0.02, -math.pi + 0.01, -math.pi + 0.03])
    assert median_offset(offsets) == pytest.approx(-math.pi + 0.01)
    assert median_offset(np.array([0.1, 0.11, 0.12, 0.13, 2.0])) == pytest.approx(0.12)
    with pytest.raises(ValueError, match="at least one"):
        median_offset(np.zeros(0))


@pytest.mark.parametrize("stall_decisions, arrives", [(5, True), (10_000, False)])
def test_drifted_tracks_are_registered_afresh_when_the_residual_stalls(stall_decisions,
                                                                        arrives):
    """The robot stands at home with its tracks drifted by 1.5 columns (median residual
    about 0.04 rad, above ``stop_tol``): the tracks never say it has arrived. After
    ``stall_decisions`` decisions without a smaller residual it registers the home frame's
    features from their stored image, which puts them back, and arrives."""
    rng = np.random.default_rng(3)
    small = rng.integers(0, 256, (12, 64, 3), dtype=np.uint8)
    panorama = np.kron(small, np.ones((4, 4, 1), np.uint8))     # 48 x 256 blocks
    controller = homing_baselines.make("bearing-longrange", stall_decisions=stall_decisions)
    controller.reset()
    controller.tracker.update(panorama)
    ids, points = controller.tracker.ids.copy(), controller.tracker.points.copy()
    controller.memory = [MemoryFrame(ids, points, controller.tracker.image)]
    controller.milestones = [0]
    controller._begin_leg(0, 0)
    drift = rng.choice([-1.5, 1.5], len(ids)) * (rng.random(len(ids)) < 0.8)
    controller.tracker.points = points + np.stack([drift, np.zeros(len(ids))], 1)
    moves = [controller.decide({}) for _ in range(stall_decisions + 1 if arrives else 20)]
    assert all(m.distance > 0 for m in moves[:stall_decisions])   # not arrived before
    assert controller._home is arrives
    if arrives:
        assert moves[-1].distance == 0 and abs(moves[-1].direction) < 0.01   # phi = 0
        err = np.abs(wrap_angle(controller.tracker.bearings() - controller._bearings()[2]))
        assert np.median(err) < 0.01


@pytest.mark.slow
def test_longrange_homes_from_pixels_and_turns_to_the_home_heading(make_env, controller_for):
    env = make_env("homing_gym/LongRangeHoming-v0", route_length=3.0, success_on="stop",
                   max_episode_steps=900)
    controller = controller_for("bearing-longrange", env)
    record = run_episode(env, controller, seed=0)
    outbound = env.unwrapped.task.outbound_steps
    assert not controller.needs_env
    assert len(controller.memory) == outbound + 1          # every frame, then G
    assert controller.milestones[-1] == 0 and len(controller.milestones) >= 3
    assert record.success and record.terminated               # stopped within 0.2 m
    assert record.final_distance < 0.1
    assert record.final_heading_error_deg < 15.0
    assert record.collisions == 0


@pytest.mark.parametrize("params, match", [
    ({"min_shared": 2}, "min_shared"),
    ({"min_shared": 101}, "min_shared"),
    ({"min_shared": 20, "klt": KLTConfig(max_features=10)}, "min_shared"),
    ({"inlier_fraction": 0.0}, "inlier_fraction"),
    ({"stall_decisions": 0}, "stall_decisions"),
    ({"klt": {"max_features": 100}}, "KLTConfig"),
    ({"stop_tol": -1.0}, "stop_tol"),
])
def test_bad_parameters_raise(params, match):
    with pytest.raises(ValueError, match=match):
        homing_baselines.make("bearing-longrange", **params)


def test_missing_phase_key_raises():
    controller = homing_baselines.make("bearing-longrange")
    with pytest.raises(ValueError, match="phase"):
        controller.predict({"panorama": np.zeros((64, 256, 3), np.uint8)})
