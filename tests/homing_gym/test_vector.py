"""The native vector env: the episodes of single envs, batched; Gymnasium's autoreset
modes; worker processes; bad input and failing envs."""

import threading

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import homing_gym
from homing_gym.vector import EnvFailedError, NativeVectorEnv

SMALL = {"panorama_shape": [16, 64], "supersampling": 1}
#: Short episodes in procedural worlds (new worlds on every automatic reset) that stop
#: often: automatic resets happen within a few steps.
SHORT = {**SMALL, "scene": "random_rooms", "action_type": "discrete", "episodes_per_world": 1}


def _native(env_id="homing_gym/LocalHoming-v0", n=3, **kwargs):
    return gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kwargs)


def _sync(env_id="homing_gym/LocalHoming-v0", n=3, max_episode_steps=None, mode=None,
          **kwargs):
    steps = {} if max_episode_steps is None else {"max_episode_steps": max_episode_steps}
    return gym.vector.SyncVectorEnv([lambda: gym.make(env_id, **kwargs, **steps)
                                     for _ in range(n)],
                                    autoreset_mode=mode or AutoresetMode.NEXT_STEP)


def _assert_same_obs(a, b):
    assert a.keys() == b.keys()
    for key in a:
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)


def _discrete_actions(steps, n, seed=0):
    """Random discrete actions, stop (3) one time in four: episodes end often."""
    return np.random.default_rng(seed).integers(0, 4, (steps, n))


@pytest.mark.parametrize("env_id", homing_gym.ENV_IDS)
def test_reset_gives_the_first_observations_of_single_envs_seeded_in_turn(env_id):
    """Env ``i`` of ``reset(seed=s)`` shows what ``gym.make(env_id).reset(seed=s + i)``
    shows, for every registered id."""
    envs = _native(env_id, 2, **SMALL)
    single = gym.make(env_id, **SMALL)
    try:
        obs, infos = envs.reset(seed=11)
        for i in range(2):
            expected, info = single.reset(seed=11 + i)
            _assert_same_obs({k: v[i] for k, v in obs.items()}, expected)
            np.testing.assert_array_equal(infos["pose"][i], info["pose"])
        assert envs.single_observation_space == single.observation_space
        assert envs.observation_space.contains(obs)
    finally:
        envs.close()
        single.close()


@pytest.mark.parametrize("processes", [1, 2])
def test_steps_and_automatic_resets_match_gymnasiums_sync_vector_env(processes):
    """NEXT_STEP (the default): 40 steps of 3 envs whose short episodes end by stop and
    by the step limit: observations, rewards, ends and poses equal SyncVectorEnv's over
    gym.make envs (same seeds), in one process and in two worker processes."""
    native = _native(n=3, max_episode_steps=9, processes=processes, **SHORT)
    sync = _sync(n=3, max_episode_steps=9, **SHORT)
    try:
        _assert_same_obs(native.reset(seed=5)[0], sync.reset(seed=5)[0])
        ends = 0
        for actions in _discrete_actions(40, 3):
            a, b = native.step(actions), sync.step(actions)
            _assert_same_obs(a[0], b[0])
            for x, y in zip(a[1:4], b[1:4]):
                np.testing.assert_array_equal(x, y)
            np.testing.assert_array_equal(a[4]["pose"], b[4]["pose"])
            np.testing.assert_array_equal(a[4]["is_success"], b[4]["is_success"])
            ends += int(np.sum(a[2] | a[3]))
        assert ends >= 6                         # automatic resets were exercised
    finally:
        native.close()
        sync.close()


def test_same_step_mode_returns_the_final_observation_and_info():
    native = _native(n=2, max_episode_steps=6, autoreset_mode="SameStep", **SHORT)
    sync = _sync(n=2, max_episode_steps=6, mode=AutoresetMode.SAME_STEP, **SHORT)
    try:
        native.reset(seed=1), sync.reset(seed=1)
        finals = 0
        for actions in _discrete_actions(20, 2, seed=2):
            a, b = native.step(actions), sync.step(actions)
            _assert_same_obs(a[0], b[0])
            np.testing.assert_array_equal(a[4].get("_final_obs", np.zeros(2, bool)),
                                          b[4].get("_final_obs", np.zeros(2, bool)))
            for i in np.flatnonzero(b[4].get("_final_obs", [])):
                finals += 1
                _assert_same_obs(a[4]["final_obs"][i], b[4]["final_obs"][i])
                assert a[4]["final_info"]["is_success"][i] == b[4]["final_info"]["is_success"][i]
        assert finals >= 3
    finally:
        native.close()
        sync.close()


def test_disabled_mode_needs_a_reset_mask_and_resets_only_those_envs():
    envs = _native(n=3, max_episode_steps=1, autoreset_mode=AutoresetMode.DISABLED, **SMALL)
    try:
        with pytest.raises(ValueError, match="first reset resets every env"):
            envs.reset(seed=0, options={"reset_mask": np.array([True, False, False])})
        obs, _ = envs.reset(seed=0)
        after, _, _, truncated, _ = envs.step(np.full((3, 2), 0.3, np.float32))
        assert truncated.all()
        with pytest.raises(RuntimeError, match=r"envs \[0, 1, 2\] ended their episodes"):
            envs.step(np.zeros((3, 2), np.float32))
        mask = np.array([False, True, False])
        again, infos = envs.reset(seed=0, options={"reset_mask": mask})
        np.testing.assert_array_equal(infos["_pose"], mask)
        _assert_same_obs({k: v[1] for k, v in again.items()}, {k: v[1] for k, v in obs.items()})
        np.testing.assert_array_equal(again["panorama"][0], after["panorama"][0])
        with pytest.raises(RuntimeError, match=r"envs \[0, 2\] ended"):
            envs.step(np.zeros((3, 2), np.float32))
    finally:
        envs.close()


def test_each_env_gets_its_own_kwargs_and_they_must_batch():
    envs = _native(n=2, env_kwargs=[{"scene": "random_rooms"}, {"scene": "random_nature"}],
                   **SMALL)
    try:
        assert [s.name for s in envs.get_attr("scene")] == ["random_rooms", "random_nature"]
        envs.set_attr("stop_threshold", [0.01, 0.02])
        assert envs.get_attr("stop_threshold") == (0.01, 0.02)
    finally:
        envs.close()
    with pytest.raises(ValueError, match=r"env 1 cannot be batched with env 0: its "
                                         r"observation_space"):
        _native(n=2, env_kwargs=[{}, {"panorama_shape": [16, 32]}], **SMALL)
    with pytest.raises(ValueError, match="max_episode_steps differ"):
        _native(n=2, env_kwargs=[{"max_episode_steps": 5}, {"max_episode_steps": 6}], **SMALL)


@pytest.mark.parametrize("kwargs, words", [
    ({"num_envs": 0}, "num_envs must be an integer from 1 to 1024, got 0"),
    ({"num_envs": -2}, "num_envs must be an integer"),
    ({"num_envs": 2.5}, "num_envs must be an integer"),
    ({"num_envs": True}, "num_envs must be an integer"),
    ({"num_envs": 2, "processes": 3}, "processes must be an integer from 1 to 2, got 3"),
    ({"num_envs": 2, "threads": 0}, "threads must be an integer from 1 to 256"),
    ({"num_envs": 2, "autoreset_mode": "Sometimes"}, "unknown autoreset_mode 'Sometimes'"),
    ({"num_envs": 2, "max_episode_steps": 0}, "max_episode_steps must be an integer >= 1"),
    ({"num_envs": 2, "env_kwargs": [{}]}, "env_kwargs must be a list of 2 dicts"),
    ({"num_envs": 2, "n_targets": 3}, "unknown keyword arguments ['n_targets']"),
])
def test_bad_settings_are_refused_by_name(kwargs, words):
    with pytest.raises(ValueError) as err:
        NativeVectorEnv("homing_gym/LocalHoming-v0", **kwargs)
    assert words in str(err.value)


def test_bad_actions_seeds_and_modes_are_refused_and_the_envs_live_on():
    envs = _native(n=3, **SMALL)
    try:
        envs.reset(seed=0)
        actions = np.zeros((3, 2), np.float32)
        actions[2, 1] = np.nan
        with pytest.raises(ValueError, match=r"the actions of envs \[2\] are not valid"):
            envs.step(actions)
        with pytest.raises(ValueError, match=r"actions must be real numbers of shape \(3, 2\)"):
            envs.step(np.zeros((2, 2), np.float32))
        with pytest.raises(ValueError, match="a list of 3 seeds"):
            envs.reset(seed=[1, 2])
        envs.step(np.zeros((3, 2), np.float32))             # still usable
    finally:
        envs.close()
    with pytest.raises(ValueError, match="Invalid vectorization mode: 'native'"):
        gym.make_vec("homing_gym/LocalHoming-v0", num_envs=2, vectorization_mode="native")


def _render_threads():
    return [t for t in threading.enumerate() if t.name.startswith("homing-render")]


def test_a_failing_env_is_named_once_and_every_env_is_closed():
    envs = _native(n=3, threads=2, **SMALL)
    envs.reset(seed=0)
    envs.unwrapped.batch.envs[1].close()                     # env 1 breaks
    with pytest.raises(EnvFailedError, match="env 1 failed: ClosedEnvironmentError") as err:
        envs.step(np.full((3, 2), 0.5, np.float32))
    assert err.value.index == 1
    assert not any(env.sim.connected for env in envs.unwrapped.batch.envs)
    assert not _render_threads()
    with pytest.raises(gym.error.ClosedEnvironmentError):
        envs.step(np.zeros((3, 2), np.float32))
    envs.close()


def test_an_env_failing_to_reset_while_the_others_render_is_named_once():
    envs = _native(n=3, threads=2, **SMALL)
    envs.reset(seed=0)
    batch = envs.unwrapped.batch

    def broken(**kwargs):
        raise RuntimeError("no world")

    batch.envs[1].reset = broken
    batch._autoreset[1] = True          # env 1's episode ended: it resets at this step
    with pytest.raises(EnvFailedError, match="env 1 failed: RuntimeError") as err:
        envs.step(np.full((3, 2), 0.5, np.float32))
    assert err.value.index == 1
    assert not any(env.sim.connected for env in batch.envs)
    assert not _render_threads()
    envs.close()


def test_a_failing_or_killed_worker_is_named_and_no_process_is_left():
    import multiprocessing as mp
    import os
    import signal

    envs = _native(n=4, processes=2, **SMALL)
    envs.reset(seed=0)
    batch = envs.unwrapped.batch
    envs.unwrapped.call("close")                     # the envs of both workers break
    with pytest.raises(EnvFailedError, match="env 0 failed: ClosedEnvironmentError"):
        envs.step(np.zeros((4, 2), np.float32))
    assert not any(p.is_alive() for p in batch._processes) and not mp.active_children()

    envs = _native(n=4, processes=2, **SMALL)
    envs.reset(seed=0)
    batch = envs.unwrapped.batch
    os.kill(batch._processes[1].pid, signal.SIGKILL)
    batch._processes[1].join()
    with pytest.raises(EnvFailedError, match=r"env 2 failed: its worker process \(envs 2-3\) "
                                             r"died with exit code -9"):
        envs.step(np.zeros((4, 2), np.float32))
    assert not mp.active_children()


def test_close_frees_every_env_and_thread():
    envs = _native(n=2, threads=2, **SMALL)
    envs.reset(seed=0)
    envs.step(np.zeros((2, 2), np.float32))
    inner = envs.unwrapped.batch.envs
    envs.close()
    envs.close()                                      # twice is fine
    assert not any(env.sim.connected for env in inner) and not _render_threads()


@pytest.mark.parametrize("processes", [1, 2])
def test_new_worlds_built_ahead_are_those_the_env_builds_itself(processes):
    """With a new world every episode and stops every step, the envs' worlds come from
    the builder process (one per worker process; all but the seeded first ones) and
    equal those single envs build themselves: the same observations step by step."""
    native = _native(n=2, processes=processes, **SHORT)
    single = [gym.make("homing_gym/LocalHoming-v0", **SHORT) for _ in range(2)]
    try:
        obs, _ = native.reset(seed=3)
        for i, env in enumerate(single):
            env.reset(seed=3 + i)
        batch = native.unwrapped.batch
        if processes == 2:
            assert len(batch.builders) == 2          # one per worker
        for _ in range(6):                    # stop, then the next step resets: new worlds
            obs = native.step(np.full(2, 3))[0]
            for i, env in enumerate(single):
                _, _, terminated, _, _ = env.step(3)
                assert terminated
            obs = native.step(np.full(2, 3))[0]
            for i, env in enumerate(single):
                _assert_same_obs({k: v[i] for k, v in obs.items()}, env.reset()[0])
        assert batch.worlds_served >= 10
    finally:
        native.close()
        for env in single:
            env.close()


def test_a_killed_worker_leaves_no_world_builder():
    """A worker's builder process ends with the batch, also after the worker was killed;
    a static world gets no builder."""
    import multiprocessing as mp
    import os
    import signal

    envs = _native(n=2, processes=2, **SHORT)
    envs.reset(seed=0)
    batch = envs.unwrapped.batch
    assert len(batch.builders) == 2 and all(p.is_alive() for p in batch.builders)
    os.kill(batch._processes[0].pid, signal.SIGKILL)
    batch._processes[0].join()
    with pytest.raises(EnvFailedError, match="env 0 failed: its worker process"):
        envs.step(np.full(2, 3))
    assert not mp.active_children()
    static = _native(n=2, processes=2, **SMALL)
    try:
        assert static.unwrapped.batch.builders == []
    finally:
        static.close()


def test_the_vector_benchmark_times_steps_resets_and_the_physics_share(capsys):
    """``homing-benchmark --vec native``: one row per configuration, vector step
    percentiles in order, resets counted (stops every 3 steps: many resets), physics and
    rendering together within a single step's time."""
    from homing_gym.benchmark import main

    main(["--vec", "native", "--num-envs", "2", "--processes", "2", "--steps", "20",
          "--episode-steps", "3", "--shapes", "48x256", "--worlds", "random_arena"])
    from homing_gym.vector import benchmark

    results = benchmark.run({"random_arena": {"scene": "random_arena"}}, 2, [1, 2], 20,
                            rounds=2, episode_steps=3, shape=(16, 64))
    single, native, workers, independent = results
    assert native.step_p50 <= native.step_p99 and 0 < native.reset_share < 1
    assert workers.step_p50 <= workers.step_p99 and workers.reset_share is None
    assert 0 < single.physics_s and single.physics_s + single.render_s < 1 / single.steps_per_s
    assert independent.config == "independent x2" and independent.steps_per_s > 0
    assert independent.step_p50 is None
    assert 0 < independent.render_scaling < 3        # 2 at best, up to noise
    out = capsys.readouterr().out
    assert "| random_arena | native, 2 envs in 2 processes |" in out and "% physics" in out
    assert "| random_arena | 2 independent processes of one env each" in out
    assert "random_arena, rendering alone in 2 independent processes at once:" in out


def test_the_benchmark_names_an_independent_process_that_died():
    from homing_gym.vector.benchmark import independent_rates

    with pytest.raises(RuntimeError, match="homing-bench-.* died with exit code 1"):
        independent_rates("homing_gym/LocalHoming-v0", {"scene": "no_such_scene"}, 2, 5, 0.0)


def _assert_same_infos(a, b):
    """Equal Gymnasium vector infos: the same keys, masks and values (nested dicts and
    object arrays of observations compared element by element)."""
    assert a.keys() == b.keys(), (sorted(a), sorted(b))
    for key in a:
        x, y = a[key], b[key]
        if isinstance(y, dict):
            _assert_same_infos(x, y)
        elif y.dtype == object:
            for u, v in zip(x, y):
                if isinstance(v, dict):
                    _assert_same_obs(u, v)
                else:
                    assert (u is None and v is None) or np.array_equal(u, v), key
        else:
            assert x.dtype == y.dtype, key
            np.testing.assert_array_equal(x, y, err_msg=key)


@pytest.mark.parametrize("mode", [AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP])
def test_infos_have_gymnasiums_layout_exactly(mode):
    """Every info key, mask, dtype and value of 25 steps with automatic resets (nested
    rewards, final observations and infos) equals what Gymnasium's SyncVectorEnv builds."""
    native = _native(n=3, max_episode_steps=5, autoreset_mode=mode, **SHORT)
    sync = _sync(n=3, max_episode_steps=5, mode=mode, **SHORT)
    try:
        _assert_same_infos(native.reset(seed=2)[1], sync.reset(seed=2)[1])
        for actions in _discrete_actions(25, 3, seed=4):
            _assert_same_infos(native.step(actions)[4], sync.step(actions)[4])
    finally:
        native.close()
        sync.close()
