"""Hong et al. 1991 (``baselines/signature.py``, ``baselines/snapshot.py``)."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

from homing_train.harness.evaluate import run_episode
from homing_train.harness.rollout import prepare_policy, rollout

import homing_baselines
from homing_baselines.motion import MotionSpec
from homing_baselines.signature import (bearing_grid, characteristic_points, monotonic_segments,
                                 signature_from_omni, signature_from_panorama)
from homing_baselines.snapshot import HongConfig, SnapshotController, harmonic_weights, hong_homing
from homing_gym.geometry import wrap_angle
from homing_train.figures.hong import render_pairs

PANORAMA = (60, 360)


def steps_signature(edges: dict[int, float], n: int = 360, base: float = 0.4) -> np.ndarray:
    """Piecewise-constant circular signature: at sample ``k`` the level changes by
    ``edges[k]`` (the changes sum to 0), each step spread over 3 samples."""
    assert abs(sum(edges.values())) < 1e-9
    v = np.full(n, base)
    for k, change in edges.items():
        ramp = np.clip((np.arange(n) - k + 1.5) / 3.0, 0, 1)   # rises over k-1 .. k+1
        v += change * ramp
    return v


@pytest.fixture(scope="module")
def hallway_views():
    env = gym.make("homing_gym/LocalHoming-v0", scene="hallway", panorama_shape=PANORAMA,
                   obs_keys=("panorama", "omni", "signature"), omni_size=256)
    obs, _ = env.reset(seed=3)
    env.close()
    return obs


# -- §2 signature -------------------------------------------------------------------------
def test_omni_and_panorama_signatures_agree(hallway_views):
    a = signature_from_panorama(hallway_views["panorama"])
    b = signature_from_omni(hallway_views["omni"])
    assert a.shape == b.shape == (360,)
    assert np.corrcoef(a, b)[0, 1] > 0.95
    assert np.abs(a - b).mean() < 0.02


def test_panorama_signature_is_the_env_signature_in_bearing_order(hallway_views):
    from homing_baselines.signature import columns_to_bearings
    np.testing.assert_allclose(signature_from_panorama(hallway_views["panorama"]),
                               columns_to_bearings(hallway_views["signature"]), atol=1e-6)
    # the bearing grid: column centres of a 360-wide panorama, counter-clockwise
    np.testing.assert_allclose(np.degrees(bearing_grid(360))[:2], [0.5, 1.5])


def test_characteristic_points_find_known_edges():
    edges = {40: 0.3, 100: -0.2, 220: 0.25, 300: -0.35}
    cp = characteristic_points(steps_signature(edges), n_points=15)
    assert cp.n_potential == 4 and len(cp) == 4
    found = sorted(int(i) for i in cp.index)
    for want, got in zip(sorted(edges), found):
        assert abs(got - want) <= 1          # the step k-1 -> k or k -> k+1
    # totals are the edge heights; rank = sparseness x total change
    by_index = dict(zip((int(i) for i in cp.index), zip(cp.total, cp.sparseness, cp.rank)))
    total, sparse, rank = by_index[min(by_index, key=lambda i: abs(i - 300))]
    assert total == pytest.approx(0.35, abs=1e-6)
    assert sparse == pytest.approx((300 - 220) + (40 + 360 - 300), abs=2)
    assert rank == pytest.approx(sparse * total)
    assert list(cp.rank) == sorted(cp.rank, reverse=True)


def test_characteristic_points_acceptance_and_top_n():
    # a small bump (edges of 0.01 instant, 0.03 total change) is below both thresholds
    edges = {60: 0.3, 120: -0.3, 150: 0.03, 200: -0.03}
    cp = characteristic_points(steps_signature(edges), min_instant=0.02, min_total=0.08)
    assert cp.n_potential == 2 and sorted(cp.index) == [59, 119]
    # accepted by total change when that threshold is low enough, or by instant change
    assert characteristic_points(steps_signature(edges), min_total=0.02).n_potential == 4
    assert characteristic_points(steps_signature(edges), min_instant=0.005).n_potential == 4
    # 30 alternating edges: only the 15 best ranked are kept
    many = {k: (0.1 if i % 2 == 0 else -0.1) * (1 + (i % 4 == 0))
            for i, k in enumerate(range(0, 360, 12))}
    many[max(many)] -= sum(many.values())
    cp = characteristic_points(steps_signature(many))
    assert cp.n_potential == 30 and len(cp) == 15
    everything = characteristic_points(steps_signature(many), n_points=100)
    np.testing.assert_allclose(cp.rank, np.sort(everything.rank)[::-1][:15])


def test_monotonic_segments_cover_the_circle():
    v = steps_signature({40: 0.3, 220: -0.3}) + 0.001 * np.sin(np.radians(np.arange(360)) * 3)
    segments = monotonic_segments(v)
    covered = np.sort(np.concatenate(segments))
    np.testing.assert_array_equal(covered, np.arange(360))
    d = np.roll(v, -1) - v
    for seg in segments:
        signs = np.sign(d[seg])
        assert np.all(signs[signs != 0] == signs[signs != 0][0])


# -- §3 matching ----------------------------------------------------------------------------
def test_harmonic_weights():
    w = harmonic_weights(13)
    assert len(w) == 13 and w[6] == pytest.approx(0.5) and w[0] == pytest.approx(1 / 8)


@pytest.mark.parametrize("shift", [3, -17, 90, 151])
def test_matching_recovers_a_circular_shift(hallway_views, shift):
    """A pure rotation of the body by ``shift`` degrees: the deviation is recovered to
    within 1 degree and every offset with the deviation removed is 0."""
    target = signature_from_panorama(hallway_views["panorama"]).astype(np.float64)
    current = np.roll(target, -shift)         # current[k] = target[k + shift]
    est = hong_homing(current, target)        # k_psi = 180: every deviation searched
    assert abs(math.degrees(wrap_angle(est.deviation - math.radians(shift)))) <= 1.0
    assert np.all(np.abs(est.offset_deg) <= 1.0)


def test_home_direction_on_rendered_pairs_in_the_arena():
    """Pairs 0.3 m apart with a common heading (Hong's body does not rotate, deviation
    searched +-10 deg): the direction error is below 30 deg for most pairs."""
    pairs = render_pairs("arena", 0.3, 24, seed=7)
    cfg = HongConfig(k_psi=10.0)
    errors = np.array([abs(math.degrees(wrap_angle(
        hong_homing(c, t, cfg, psi_prior=0.0).direction - truth)))
        for c, t, truth in zip(pairs.current, pairs.target, pairs.truth)])
    assert np.median(errors) < 30
    assert np.mean(errors < 30) >= 0.6


def test_config_validation():
    with pytest.raises(ValueError, match="window"):
        HongConfig(window=12)
    with pytest.raises(ValueError, match="k_psi"):
        HongConfig(k_psi=200.0)
    with pytest.raises(ValueError, match="target_stats"):
        HongConfig(target_stats="nowhere")
    with pytest.raises(ValueError, match="source"):
        SnapshotController(source="camera")
    with pytest.raises(ValueError, match="stop_angle"):
        SnapshotController(stop_angle=0.0)


# -- the controller -------------------------------------------------------------------------
def test_registered_and_needs_its_observation_keys():
    controller = homing_baselines.make("snapshot", k_back=20.0)
    assert isinstance(controller, SnapshotController)
    with pytest.raises(ValueError, match="goal_omni"):
        homing_baselines.make("snapshot", source="omni").decide({"panorama": np.zeros((60, 360, 3))})


def test_started_at_home_it_stops_near_home(make_env):
    """§4's stop rule at the goal itself: the first step (0.6 ft) leaves home, the next
    estimate points back (the direction reverses), and the robot stops there, about one
    first step away (so not within the 0.15 m radius: the method stops after the
    overshoot it detects)."""
    env = make_env(scene="hallway", panorama_shape=PANORAMA, success_on="stop",
                   max_episode_steps=200)
    for seed in (3, 4, 5):
        env.reset(seed=seed)
        home = env.unwrapped.episode.home
        c = SnapshotController()
        prepare_policy(c, env)
        record = run_episode(env, c, seed, start=home, home=home)
        assert record.terminated and not record.truncated
        assert record.final_distance < 0.6 * 0.3048 + 0.02, (seed, record.final_distance)
        assert record.steps < 60


def test_stays_stopped_until_the_goal_changes(hallway_views):
    c = SnapshotController()
    c.configure(MotionSpec())
    c.reset(0)
    pano = hallway_views["panorama"]
    c._stopped, c._goal = True, pano.copy()      # as after the stop rule fired
    assert all(c.decide({"panorama": pano, "goal": pano}) is None for _ in range(3))
    shifted = np.roll(pano, 20, axis=1)
    move = c.decide({"panorama": pano, "goal": shifted})
    assert move is not None and move.distance == pytest.approx(0.6 * 0.3048)


def test_route_first_targets_in_stop_mode(make_env):
    """The paper's setting (§5): from 1 ft before the first target the robot homes to
    each target in turn and decides itself when it has arrived."""
    env = make_env("homing_gym/RouteFollowing-v0", panorama_shape=PANORAMA, n_targets=3,
                   success_on="stop")
    c = SnapshotController()
    c.configure(MotionSpec.from_env(env))
    obs, _ = env.reset(seed=0)
    c.reset(0)
    done = False
    while not done:
        action, _ = c.predict(obs)
        obs, _, terminated, truncated, info = env.step(action)
        done = terminated or truncated
    assert len(info["target_errors"]) == 3
    assert max(info["target_errors"]) < 0.15


@pytest.mark.slow
def test_route_of_17_targets_on_the_synchro_drive(make_env):
    """The paper's demonstration on its robot (§5; the body never turns): 17 targets 1 ft
    apart, each stop decided by the §4 rule. The last target is reached in every route
    (40 of 40 routes in docs/hong.md) and no stop is half a spacing (0.15 m) off; before
    the body was known to keep its heading, the estimated deviation drifted by tens of
    degrees and seed 2 stopped 0.35 m from target 16 and 0.33 m from the last."""
    env = make_env("homing_gym/RouteFollowing-v0", panorama_shape=PANORAMA, drive="synchro",
                   start_jitter=(0.05, 0.0), success_on="stop")
    c = SnapshotController()
    prepare_policy(c, env)
    for seed in (0, 1, 2):
        errors = rollout(env, c, seed).info["target_errors"]
        assert len(errors) == 17 and errors[-1] < 0.1, (seed, errors)
        assert max(errors) < 0.15, (seed, errors)


@pytest.mark.xfail(strict=True, reason="Hong's capture region in the 'arena' (four identical "
                   "red cylinders 0.5 m from its centre) is smaller than 0.5 m: see docs/hong.md")
def test_controller_reaches_home_from_half_a_metre_in_the_arena(make_env):
    env = make_env(panorama_shape=PANORAMA, start_distance=(0.5, 0.5), success_on="stop")
    from homing_train.harness.evaluate import run_episode
    from homing_train.harness.rollout import prepare_policy, rollout

    c = SnapshotController()
    prepare_policy(c, env)
    successes = sum(run_episode(env, c, seed).success for seed in range(4))
    assert successes >= 3
