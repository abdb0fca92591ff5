"""The start-distance (and success-radius) curriculum of homing-train: promotion on the
success rate of the last finished episodes, the env hook it drives, and its settings' checks."""

import json
import math

import gymnasium as gym
import numpy as np
import pytest

from homing_train.learning.curriculum import CurriculumSettings, last_stage, mark_stages, stage_key
from homing_train.learning.curriculum_callback import CurriculumCallback
from homing_train.learning.train import check_curriculum, main, make_config, make_monitored_env

STAGES = [[0.15, 0.35], [0.2, 0.6], [0.3, 1.5]]


class OneStepEnv(gym.Env):
    """Episodes of one step; every ``period``-th episode of this env is a success while
    the start distance's maximum is below ``easy`` m, none beyond it."""

    observation_space = gym.spaces.Box(-1, 1, (2,), np.float32)
    action_space = gym.spaces.Discrete(2)

    def __init__(self, period: int = 1, easy: float = 0.5):
        self.period, self.easy = period, easy
        self.start_distance = (0.3, 1.5)
        self.success_radius = 0.15
        self.episodes = 0

    def set_start_distance(self, start_distance, success_radius=None):
        self.start_distance = tuple(start_distance)
        if success_radius is not None:
            self.success_radius = success_radius

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return np.zeros(2, np.float32), {}

    def step(self, action):
        self.episodes += 1
        success = self.start_distance[1] < self.easy and self.episodes % self.period == 0
        return np.zeros(2, np.float32), float(success), True, False, {"is_success": success}


class NoHookEnv(OneStepEnv):
    set_start_distance = None


gym.register("curriculum_test/OneStep-v0", entry_point=OneStepEnv)


def _learn(tmp_path, period, promote_at, window=8, steps=256, **settings):
    """PPO on two monitored :class:`OneStepEnv` (wrapped as homing-train wraps its envs)
    with the curriculum callback (more ``settings`` of it as keywords); returns the
    callback and the vector env."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv

    env = DummyVecEnv([lambda: make_monitored_env("curriculum_test/OneStep-v0",
                                                  {"period": period})] * 2)
    settings = CurriculumSettings.from_value({"start_distance": STAGES,
                                              "promote_at": promote_at, "window": window,
                                              **settings})
    callback = CurriculumCallback(settings, tmp_path / "curriculum.json")
    PPO("MlpPolicy", env, n_steps=32, batch_size=32, n_epochs=1, seed=0).learn(
        steps, callback=callback)
    return callback, env


@pytest.mark.parametrize("period, promote_at, promoted", [
    (1, 0.5, True),         # every episode a success
    (4, 0.25, True),        # one in four: exactly the threshold
    (4, 0.3, False),        # one in four: below it
])
def test_the_stage_advances_when_the_window_success_rate_reaches_promote_at(
        tmp_path, period, promote_at, promoted):
    callback, env = _learn(tmp_path, period, promote_at)
    # stage 1 (max 0.6 m) is beyond OneStepEnv's easy 0.5 m: no success there, no stage 2
    stage = 1 if promoted else 0
    assert callback.stage == stage
    assert env.get_attr("start_distance") == [tuple(STAGES[stage])] * 2
    record = json.loads((tmp_path / "curriculum.json").read_text())
    assert [s["stage"] for s in record["stages"]] == list(range(stage + 1))
    assert record["stages"][0]["from_step"] == 0
    if promoted:    # a full window (8 episodes of 1 step, 2 envs) before the promotion
        assert 8 <= record["stages"][1]["from_step"] <= 8 + 2 * period
        assert callback.success_rate == 0.0     # the window restarted at stage 1
    assert last_stage(tmp_path / "curriculum.json") == (stage, record["stages"])


def test_a_stage_sets_its_success_radius_on_the_envs_and_in_the_record(tmp_path):
    callback, env = _learn(tmp_path, 1, 0.5, success_radius=[0.3, 0.2, 0.15])
    assert callback.stage == 1
    assert env.get_attr("success_radius") == [0.2, 0.2]
    record = json.loads((tmp_path / "curriculum.json").read_text())
    assert record["settings"]["success_radius"] == [0.3, 0.2, 0.15]
    assert [(s["stage"], s["success_radius"]) for s in record["stages"]] == [(0, 0.3), (1, 0.2)]


def test_set_start_distance_can_change_the_success_radius_with_it():
    env = gym.make("homing_gym/LocalHoming-v0", panorama_shape=(16, 64))
    task = env.unwrapped.task
    env.unwrapped.set_start_distance((0.4, 0.6), success_radius=0.4)
    assert (task.start_distance, task.success_radius) == ((0.4, 0.6), 0.4)
    _, info = env.reset(seed=3)
    assert 0.4 <= math.dist(info["start_pose"][:2], info["home_pose"][:2]) <= 0.6
    # both are checked together; a refusal changes neither
    for bad, radius, message in (((0.3, 0.6), 0.35, "must start at or beyond success_radius 0.35"),
                                 ((0.4, 0.6), 0.0, "success_radius"),
                                 ((0.4, 0.6), math.nan, "success_radius"),
                                 ((0.5, 9.0), 0.3, "does not fit")):
        with pytest.raises(ValueError, match=message):
            env.unwrapped.set_start_distance(bad, success_radius=radius)
        assert (task.start_distance, task.success_radius) == ((0.4, 0.6), 0.4)
    env.close()


def test_set_start_distance_changes_the_sampled_start_distances():
    env = gym.make("homing_gym/LocalHoming-v0", panorama_shape=(16, 64))

    def start_distances():
        out = []
        for seed in range(12):
            _, info = env.reset(seed=seed)
            out.append(math.dist(info["start_pose"][:2], info["home_pose"][:2]))
        return np.array(out)

    default = start_distances()
    assert np.all((default > 0.29) & (default < 1.51)) and np.any(default > 1.0)
    env.get_wrapper_attr("set_start_distance")((0.9, 1.0))  # as VecEnv.env_method reaches it
    near = start_distances()
    assert np.all((near > 0.89) & (near < 1.01)), near
    # refused values leave the range as it was
    for bad, message in (((0.1, 0.3), "success_radius"), ((0.3, 9.0), "does not fit"),
                         ((1.0, 0.5), "0 <= min <= max"), ((0.3,), "min, max")):
        with pytest.raises(ValueError, match=message):
            env.unwrapped.set_start_distance(bad)
        assert env.unwrapped.task.start_distance == (0.9, 1.0)
    env.close()


@pytest.mark.parametrize("curriculum, message", [
    ([[0.2, 0.5]], "mapping"),
    ({"start_distance": STAGES, "promote": 0.5}, "unknown curriculum settings"),
    ({"start_distance": []}, "start_distance"),
    ({"promote_at": 0.5}, "start_distance"),
    ({"start_distance": [[0.5, 0.3]]}, r"0 <= min <= max, got \[\[0.5, 0.3\]\]"),
    ({"start_distance": [[0.2, "far"]]}, "start_distance"),
    ({"start_distance": [0.2, 0.5]}, "start_distance"),
    ({"start_distance": STAGES, "promote_at": 0}, r"promote_at .*\(0, 1\], got 0"),
    ({"start_distance": STAGES, "promote_at": 1.5}, "promote_at"),
    ({"start_distance": STAGES, "window": 0}, r"window must be an integer >= 1 .*got 0"),
    ({"start_distance": STAGES, "window": 2.5}, "window"),
    ({"start_distance": STAGES, "window": True}, "window"),
    ({"start_distance": STAGES, "success_radius": [0.2, 0.15]},
     r"success_radius must be a list of 3 positive radii"),
    ({"start_distance": STAGES, "success_radius": [0.2, 0.15, 0]}, "success_radius"),
    ({"start_distance": STAGES, "success_radius": 0.15}, "success_radius"),
])
def test_bad_curriculum_settings_raise_value_error(curriculum, message):
    with pytest.raises(ValueError, match=message):
        make_config("homing_gym/LocalHoming-v0", {"curriculum": curriculum})


def test_stages_the_env_refuses_and_envs_without_the_hook_are_errors(tmp_path, capsys):
    env = gym.make("homing_gym/LocalHoming-v0", panorama_shape=(16, 64))
    # stage 1 starts inside the success radius (0.15 m)
    with pytest.raises(ValueError, match=r"curriculum stage 1: .*success_radius"):
        check_curriculum(env.unwrapped, CurriculumSettings.from_value(
            {"start_distance": [[0.2, 0.5], [0.1, 0.5]]}))
    # stage 0 starts inside its own success radius (0.4 m)
    with pytest.raises(ValueError, match=r"curriculum stage 0: .*success_radius 0.4"):
        check_curriculum(env.unwrapped, CurriculumSettings.from_value(
            {"start_distance": [[0.3, 1.5]], "success_radius": [0.4]}))
    env.close()
    with pytest.raises(ValueError, match="has no set_start_distance"):
        check_curriculum(NoHookEnv(), CurriculumSettings.from_value({"start_distance": STAGES}))
    # homing-train says it before writing the run folder
    run = tmp_path / "run"
    with pytest.raises(SystemExit):
        main(["--out", str(run), "--env-kwargs", json.dumps({"panorama_shape": [16, 64]}),
              "--hp", "curriculum={start_distance: [[0.3, 9.0]]}"])
    assert "curriculum stage 0" in capsys.readouterr().err and not run.exists()


def test_a_run_logs_its_stages_and_a_resumed_run_goes_on_at_its_last_stage(tmp_path):
    from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

    run = tmp_path / "run"
    tiny = ["--env-kwargs", json.dumps({"panorama_shape": [16, 64], "max_episode_steps": 16}),
            "--n-envs", "1", "--vec", "dummy", "--no-progress", "--extractor", "band",
            "--hp", "n_steps=64", "--hp", "batch_size=32", "--hp", "n_epochs=1",
            "--hp", "eval_freq=64", "--hp", "eval_episodes=1", "--hp", "checkpoint_freq=64",
            "--hp", "features_dim=32",
            "--hp", "curriculum={start_distance: [[0.2, 0.4], [0.3, 1.5]], window: 1000}"]
    main(["--timesteps", "64", "--out", str(run), *tiny])
    path = run / "curriculum.json"
    record = json.loads(path.read_text())
    assert record["stages"] == [{"stage": 0, "start_distance": [0.2, 0.4], "from_step": 0}]
    # as if the first session had reached stage 1
    record["stages"].append({"stage": 1, "start_distance": [0.3, 1.5], "from_step": 40})
    path.write_text(json.dumps(record))
    main(["--resume", str(run), "--timesteps", "128", "--no-progress"])
    assert json.loads(path.read_text())["stages"] == record["stages"]
    stages = []
    for events in sorted((run / "tb").glob("ppo_*")):
        accumulator = EventAccumulator(str(events))
        accumulator.Reload()
        stages += [e.value for e in accumulator.Scalars("curriculum/stage")]
    assert stages == [0, 1]         # one rollout per session
    assert (run / "learning_curve.png").is_file()


def test_stage_marks_share_a_label_when_too_close_to_read_apart():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    stages = [{"stage": k, "from_step": step, "start_distance": [0.3, 1.5],
               "success_radius": 0.15} for k, step in
              enumerate([0, 180_000, 216_000, 250_000, 1_500_000])]
    fig, ax = plt.subplots()
    ax.plot([0, 3_000_000], [0, 1])
    mark_stages(ax, stages)
    assert [t.get_text() for t in ax.texts] == ["1-3", "4"]
    assert len(ax.lines) == 1 + 4
    plt.close(fig)
    assert stage_key(stages[:2]).splitlines() == [
        "stage 0 from 0k: 0.3-1.5 m, radius 0.15 m", "stage 1 from 180k: 0.3-1.5 m, radius 0.15 m"]


@pytest.mark.parametrize("text", ["{", "[]", '{"stages": 3}', '{"stages": [{"x": 1}]}',
                                  '{"stages": [{"stage": -1}]}', '{"stages": [{"stage": true}]}'])
def test_a_broken_curriculum_record_is_one_error_naming_the_file(tmp_path, text):
    path = tmp_path / "curriculum.json"
    path.write_text(text)
    with pytest.raises(ValueError, match="curriculum.json"):
        last_stage(path)


def test_a_curriculum_record_gives_its_last_stage(tmp_path):
    path = tmp_path / "curriculum.json"
    path.write_text(json.dumps({"stages": [{"stage": 0}, {"stage": 2}]}))
    assert last_stage(path) == (2, [{"stage": 0}, {"stage": 2}])
