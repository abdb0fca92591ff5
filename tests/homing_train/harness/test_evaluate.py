"""The harness: paired episodes, information isolation, JSON/CSV, CLIs, pictures."""

import csv
import dataclasses
import json
import math
import re
from dataclasses import dataclass
from typing import ClassVar

import gymnasium as gym
import numpy as np
import pytest

from homing_baselines import Controller
from homing_baselines.motion import Move
from homing_train.harness import compare as compare_cli
from homing_train.harness import eval_command as eval_cli
from homing_train.harness import field as field_cli
from homing_train.harness.evaluate import EvalResult, evaluate, run_episode
from homing_train.harness.policies import policy_spec

ENV_ID = "homing_gym/LocalHoming-v0"
SHORT = {"max_episode_steps": 8}


@dataclass
class SpyController(Controller):
    """Records every argument it is handed; refuses the env like any non-oracle."""

    calls: ClassVar[list] = []

    def decide(self, observation):
        return Move(0.5, 0.1)

    def predict(self, observation, state=None, episode_start=None, deterministic=True):
        SpyController.calls.append((observation, state, episode_start, deterministic))
        return super().predict(observation, state, episode_start, deterministic)


def _walk(obj, depth=0):
    """Every object reachable through containers and instance attributes."""
    yield obj
    if depth > 4:
        return
    if isinstance(obj, dict):
        children = list(obj.values())
    elif isinstance(obj, (list, tuple)):
        children = list(obj)
    elif hasattr(obj, "__dict__") and not isinstance(obj, type):
        children = list(vars(obj).values())
    else:
        children = []
    for child in children:
        yield from _walk(child, depth + 1)


def test_non_oracle_controllers_get_only_the_observation():
    SpyController.calls.clear()
    spy = SpyController()
    evaluate(spy, ENV_ID, episodes=2, seed=0, env_kwargs=SHORT, progress=False)
    assert len(SpyController.calls) == 2 * SHORT["max_episode_steps"]
    for observation, state, episode_start, _ in SpyController.calls:
        assert set(observation) == {"panorama", "goal"}
        assert all(isinstance(v, np.ndarray) for v in observation.values())
        assert state is None and isinstance(episode_start, bool)
    # nothing the controller holds or was handed leads to the env, its simulator or info
    forbidden = (gym.Env,)
    from homing_gym.sim.simulator import Simulator
    for obj in list(_walk(SpyController.calls)) + list(_walk(spy)):
        assert not isinstance(obj, forbidden + (Simulator,))
        assert not (isinstance(obj, dict) and {"pose", "goal_pose"} & set(obj))


def test_same_seed_gives_identical_episodes_across_policies():
    a = evaluate("oracle", ENV_ID, episodes=3, seed=11, env_kwargs=SHORT, progress=False)
    b = evaluate("random", ENV_ID, episodes=3, seed=11, env_kwargs=SHORT, progress=False)
    assert [e.seed for e in a.episodes] == [11, 12, 13]
    assert [e.start_pose for e in a.episodes] == [e.start_pose for e in b.episodes]
    assert [e.home_pose for e in a.episodes] == [e.home_pose for e in b.episodes]
    assert len({tuple(e.home_pose) for e in a.episodes}) == 3
    c = evaluate("random", ENV_ID, episodes=1, seed=12, env_kwargs=SHORT, progress=False)
    assert c.episodes[0].start_pose == b.episodes[1].start_pose


def test_workers_give_the_same_records_as_one_process():
    one = evaluate("random", ENV_ID, episodes=3, seed=0, env_kwargs=SHORT, progress=False)
    two = evaluate("random", ENV_ID, episodes=3, seed=0, env_kwargs=SHORT, workers=2,
                   progress=False)
    strip = lambda r: [(e.seed, e.trajectory, e.success) for e in r.episodes]  # noqa: E731
    assert strip(one) == strip(two)


@dataclass
class CountingController(Controller):
    """Counts the episodes it has seen in its process: a memory across episodes."""

    seen: int = 0

    def keeps_memory_across_episodes(self) -> bool:
        return True

    def on_reset(self) -> None:
        self.seen += 1

    def decide(self, observation):
        return Move(0.0, 0.1 * self.seen)


def test_a_controller_with_memory_runs_its_episodes_in_order_in_one_process(monkeypatch):
    """Its episodes depend on the ones before, so workers must not split them: the
    records are those of one sequence (moves growing with the episode count) and no
    process pool is started."""
    import homing_train.harness.evaluate as evaluate_module

    def no_pool(*args, **kwargs):
        raise AssertionError("a process pool was started")

    monkeypatch.setattr(evaluate_module, "pool_results", no_pool)
    spec = policy_spec(CountingController())
    assert spec.sequential and not policy_spec("random").sequential
    result = evaluate(spec, ENV_ID, episodes=3, seed=0, env_kwargs=SHORT, workers=2,
                      progress=False)
    travelled = [sum(math.dist(a[:2], b[:2]) for a, b in zip(e.trajectory, e.trajectory[1:]))
                 for e in result.episodes]
    assert travelled[0] < travelled[1] < travelled[2], travelled


def test_eval_cli_writes_json_and_csv(tmp_path, capsys):
    out = tmp_path / "r.json"
    assert eval_cli.main(["--policy", "random", "--param", "step_length=0.15", "--episodes", "2",
                          "--seed", "4", "--env-kwargs", json.dumps(SHORT), "--quiet",
                          "--out", str(out)]) == 0
    doc = json.loads(out.read_text())
    assert doc["schema"] == 1 and doc["policy"] == "random" and doc["seed"] == 4
    assert doc["params"]["step_length"] == 0.15
    assert doc["env_kwargs"] == {**SHORT, "obs_keys": ["panorama", "goal"],     # recorded as used
                                 "renderer": "raycast", "physics_substeps": 12,
                                 "success_on": "stop"}
    assert doc["success_on"] == "stop"                  # the rule, stated at the top too
    assert "random on homing_gym/LocalHoming-v0: 2 episodes, success (stopped at the goal) " \
        in capsys.readouterr().out
    for key in ("episodes", "success_rate", "success_ci", "spl", "soft_spl",
                "final_distance_mean", "path_length_mean", "steps_mean", "success_by_distance"):
        assert key in doc["summary"]
    assert [e["seed"] for e in doc["episodes"]] == [4, 5]
    assert all(e["steps"] == 8 and len(e["trajectory"]) == 9 for e in doc["episodes"])
    rows = list(csv.DictReader(open(tmp_path / "r.csv")))
    assert [r["seed"] for r in rows] == ["4", "5"] and "trajectory" not in rows[0]
    assert [r["success_on"] for r in rows] == ["stop", "stop"]
    assert EvalResult.load(str(out)).summary == doc["summary"]


@pytest.mark.parametrize("argv, message", [
    (["--policy", "nope"], "oracle"),
    (["--policy", "oracle", "--param", "oops"], "key=value"),
    (["--policy", "oracle", "--env-kwargs", "{bad"], "JSON object"),
])
def test_eval_cli_rejects_bad_input(tmp_path, capsys, argv, message):
    with pytest.raises(SystemExit) as err:
        eval_cli.main(argv + ["--out", str(tmp_path / "x.json")])
    assert err.value.code == 2
    assert message in capsys.readouterr().err


@pytest.mark.parametrize("argv, message", [
    (["--env-kwargs", '{"bogus": 1}'], "unknown keyword arguments ['bogus']"),
    (["--env-kwargs", '{"scene": "moon"}'], "unknown scene 'moon'"),
    (["--workers", "0"], "a number of workers is an integer >= 1"),
    (["--bin-width", "-1"], "bin width must be a positive number"),
    (["--seed", "-5"], "a seed is an integer >= 0"),
])
def test_a_failed_evaluation_is_one_line_and_leaves_no_file(tmp_path, capsys, argv, message):
    with pytest.raises(SystemExit) as err:
        eval_cli.main(["--policy", "oracle", "--episodes", "1", "--quiet", *argv,
                       "--out", str(tmp_path / "x.json")])
    assert err.value.code == 2
    lines = [line for line in capsys.readouterr().err.splitlines() if "error:" in line]
    assert len(lines) == 1 and message in lines[0]
    # no header-only episode stream left behind to block a later --resume
    assert list(tmp_path.iterdir()) == []


def test_compare_and_suite_refuse_bad_input_before_writing(tmp_path, capsys):
    from homing_train.harness import compare as compare_cli
    from homing_train.harness import suite as suite_cli
    binary = tmp_path / "binary.json"
    binary.write_bytes(bytes(range(256)))
    for argv, message in (([str(binary), "--out", str(tmp_path / "c")], "binary.json: not a "
                           "readable result JSON"),
                          ([str(binary), "--trajectories", "-1", "--out", str(tmp_path / "c")],
                           "trajectories must be >= 0"),
                          ([str(binary), "--out", str(binary)], "is a file")):
        with pytest.raises(SystemExit) as err:
            compare_cli.main(argv)
        assert err.value.code == 2 and message in capsys.readouterr().err
    for argv, message in ((["--env", "nope/X-v0"], "unknown env id 'nope/X-v0'"),
                          (["--methods", "nope"], "unknown methods ['nope']")):
        with pytest.raises(SystemExit) as err:
            suite_cli.main([*argv, "--episodes", "1", "--out", str(tmp_path / "suite")])
        assert err.value.code == 2 and message in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["binary.json"]


def test_field_refuses_a_grid_too_fine_to_run(tmp_path, capsys):
    from homing_train.harness import field as field_cli
    with pytest.raises(SystemExit) as err:
        field_cli.main(["--policy", "oracle", "--grid", "1e-6", "--no-return",
                        "--out", str(tmp_path / "f.png")])
    assert err.value.code == 2
    # 2.4 m / 1e-6 m = 2.4 million columns and rows
    assert "gives 5760000000000 points; at most 20000" in capsys.readouterr().err


def test_load_rejects_bad_json(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(ValueError, match="bad.json"):
        EvalResult.load(str(bad))
    bad.write_text(json.dumps({"schema": 99}))
    with pytest.raises(ValueError, match="schema"):
        EvalResult.load(str(bad))


def test_compare_writes_table_and_pngs(tmp_path):
    paths = []
    for name in ("oracle", "random"):
        r = evaluate(name, ENV_ID, episodes=2, seed=0, env_kwargs={"max_episode_steps": 40},
                     progress=False)
        paths.append(str(tmp_path / f"{name}.json"))
        r.save(paths[-1])
    assert compare_cli.main(paths + ["--out", str(tmp_path / "cmp"), "--trajectories", "2"]) == 0
    table = (tmp_path / "cmp" / "table.md").read_text().splitlines()
    assert table[0] == ("Success rule: LocalHoming-v0, success_on='stop' (stopped at the goal "
                        "within 0.15 m).")
    assert table[4].startswith("| oracle |") and table[5].startswith("| random |")
    for line, path in zip(table[4:6], paths):    # each cell is its result's own value
        s = EvalResult.load(path).summary
        cells = [c.strip() for c in line.strip("|").split("|")]
        assert cells[1] == str(s["episodes"])
        assert cells[2].startswith(f"{100 * s['success_rate']:.1f} [")
        assert cells[3].startswith(f"{s['spl']:.3f} [")
        assert cells[4].startswith(f"{s['soft_spl']:.3f} [")
        assert cells[5].startswith(f"{100 * s['final_distance_mean']:.1f} [")
    for png in ("success_vs_distance.png", "final_distance.png", "trajectories.png"):
        assert (tmp_path / "cmp" / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_compare_refuses_rows_scored_under_different_rules_and_notes_unpaired_seeds(tmp_path):
    from homing_train.harness.compare import compare
    runs = {"stop": ({}, 0), "reach": ({"success_on": "reach"}, 0),        # stop: the default
            "wide": ({"success_radius": 0.3}, 0), "later": ({"success_on": "stop"}, 5)}
    paths = {}
    for name, (kwargs, seed) in runs.items():
        r = evaluate("oracle", ENV_ID, episodes=2, seed=seed, progress=False,
                     env_kwargs={"max_episode_steps": 40, **kwargs})
        paths[name] = str(tmp_path / f"{name}.json")
        r.save(paths[name])
    for other in ("reach", "wide"):
        with pytest.raises(ValueError, match="different success rules") as err:
            compare([paths["stop"], paths[other]], str(tmp_path / "cmp"))
        assert "success_on='stop', success_radius=0.15" in str(err.value)
    assert not (tmp_path / "cmp").exists()
    compare([paths["stop"], paths["later"]], str(tmp_path / "cmp"))    # default == explicit
    assert ("the results cover different episode seeds, 0 shared"
            in (tmp_path / "cmp" / "table.md").read_text())


@pytest.mark.slow
def test_field_of_oracle_points_home_and_random_does_not(tmp_path):
    out = tmp_path / "field.png"
    assert field_cli.main(["--policy", "oracle", "--grid", "0.6", "--quiet",
                           "--out", str(out)]) == 0
    assert out.read_bytes()[:4] == b"\x89PNG"
    scores = json.loads((tmp_path / "field.json").read_text())
    assert len(scores["points"]) >= 8
    assert scores["aae_deg"] < 25 and scores["homeward"] > 0.85
    assert scores["return_ratio"] == 1.0
    rnd = field_cli.homing_field("random", grid=0.6, run_to_end=False, progress=False)
    assert rnd.aae_deg > 45 and rnd.return_ratio is None


def test_sb3_model_zip_is_evaluated(tmp_path):
    sb3 = pytest.importorskip("stable_baselines3")
    env = gym.make(ENV_ID)
    model = sb3.PPO("MultiInputPolicy", env, n_steps=8, batch_size=8, device="cpu")
    path = tmp_path / "ppo_tiny.zip"
    model.save(path)
    env.close()
    result = evaluate(str(path), ENV_ID, episodes=1, seed=0, progress=False,   # to the limit:
                      env_kwargs={"max_episode_steps": 3, "success_on": "reach"})  # no stop
    assert result.policy == "ppo_tiny" and result.episodes[0].steps == 3
    with pytest.raises(ValueError, match="observation_space"):
        evaluate(str(path), ENV_ID, episodes=1, env_kwargs={"obs_keys": ["signature"]},
                 progress=False)


def test_evaluate_gives_a_controller_the_observation_keys_it_reads():
    from homing_train.harness.evaluate import evaluate

    result = evaluate("distance", episodes=1, seed=3, workers=1, progress=False,
                      env_kwargs={"max_episode_steps": 3})
    assert result.env_kwargs["obs_keys"] == ["panorama", "goal", "goal_step"]
    chosen = evaluate("distance", episodes=1, seed=3, workers=1, progress=False,
                      env_kwargs={"max_episode_steps": 3, "obs_keys": ["panorama", "goal"]})
    assert chosen.env_kwargs["obs_keys"] == ["panorama", "goal"]
    assert chosen.episodes[0].start_pose == result.episodes[0].start_pose


def test_missing_training_extra_is_one_line_and_the_suite_runs_without_it(monkeypatch, capsys,
                                                                          tmp_path):
    import importlib.util

    from homing_train.harness import suite
    from homing_train.learning import train as train_cli

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "stable_baselines3" else real(name, *a))
    with pytest.raises(SystemExit) as exit_:
        train_cli.main(["--timesteps", "8"])
    assert exit_.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and 'pip install "homing-gym[train]"' in err
    suite.run_suite(tmp_path, episodes=1, workers=1, methods=["random"])
    out = capsys.readouterr().out
    assert "learned rows ['ppo_procedural_imitation', 'ppo_procedural_long'] are left out" in out
    assert not (tmp_path / "ppo_procedural_long.json").exists()


def test_the_suite_gives_a_shipped_policy_the_controllers_time(monkeypatch, tmp_path):
    """ppo_procedural_long trained with 200 steps of 0.2 s; beside the controllers' 500 steps
    of 0.1 s it gets 250 of its own, not the 200 of its record."""
    from homing_train.harness import suite

    seen = {}

    def fake_evaluate(policy, env_id, env_kwargs=None, **kwargs):
        seen[policy] = dict(env_kwargs or {})
        raise KeyboardInterrupt          # the arguments are all this test needs

    monkeypatch.setattr(suite, "evaluate", fake_evaluate)
    with pytest.raises(KeyboardInterrupt):
        suite.run_suite(tmp_path, episodes=1, workers=1, methods=["ppo_procedural_long"])
    (kwargs,) = seen.values()
    assert kwargs["control_period"] == 0.2 and kwargs["max_episode_steps"] == 250


def test_the_suite_runs_a_model_zip_by_path_under_its_input_format_only(tmp_path):
    """A run folder's zip (trained with 16 x 64 panoramas, a 16-step cap and the camera
    at 0.1 m) is a row beside the controllers: its input format, the suite's world, rule
    and time (500 steps of 0.1 s), not its camera."""
    from homing_train.harness import suite
    from homing_train.learning.train import main as train_main

    run = tmp_path / "run"
    train_main(["--timesteps", "64", "--out", str(run), "--extractor", "band", "--n-envs", "1",
                "--vec", "dummy", "--no-progress", "--env-kwargs",
                json.dumps({"panorama_shape": [16, 64], "max_episode_steps": 16,
                            "camera_height": 0.1}),
                "--hp", "n_steps=64", "--hp", "batch_size=32", "--hp", "n_epochs=1",
                "--hp", "features_dim=32"])
    model = str(run / "model.zip")
    suite.run_suite(tmp_path / "out", episodes=1, workers=1, methods=["random", model])
    stem = suite.result_stem(model)
    assert "/" not in stem and stem.endswith("run_model")
    kwargs = json.loads((tmp_path / "out" / f"{stem}.json").read_text())["env_kwargs"]
    assert kwargs["panorama_shape"] == [16, 64] and kwargs["success_on"] == "stop"
    assert kwargs["max_episode_steps"] == 500 and "camera_height" not in kwargs
    with pytest.raises(ValueError, match="or the path of a PPO model .zip"):
        suite.run_suite(tmp_path / "x", episodes=1, workers=1,
                        methods=[str(tmp_path / "missing.zip")])


@pytest.mark.parametrize("rule", ["stop", "reach"])
def test_every_row_of_the_suite_has_one_success_rule(monkeypatch, tmp_path, rule):
    # ppo_procedural_long trained with success_on="stop"; a controller row has no rule of its
    # own: both get the suite's
    from homing_train.harness import suite

    seen = {}

    class Stub:
        def save(self, path):
            pass

    def fake_evaluate(policy, env_id, env_kwargs=None, **kwargs):
        seen[policy.split("/")[-1]] = dict(env_kwargs or {})
        if len(seen) == 2:
            raise KeyboardInterrupt      # the arguments are all this test needs
        return Stub()

    monkeypatch.setattr(suite, "evaluate", fake_evaluate)
    monkeypatch.setattr(suite, "format_summary", lambda result: "")
    with pytest.raises(KeyboardInterrupt):
        suite.run_suite(tmp_path, episodes=1, workers=1,
                        methods=["warping", "ppo_procedural_long"], success_on=rule)
    assert {name: kwargs["success_on"] for name, kwargs in seen.items()} == {
        "warping": rule, "ppo_procedural_long.zip": rule}


def _without_wall_time(result):
    return [{k: v for k, v in dataclasses.asdict(e).items() if k != "wall_time"}
            for e in result.episodes]


def test_an_interrupted_evaluation_resumes_to_the_uninterrupted_result(tmp_path):
    from homing_train.harness.evaluate import evaluate

    kwargs = {"max_episode_steps": 20, "panorama_shape": [16, 64]}
    full = evaluate("random", episodes=4, seed=7, env_kwargs=kwargs, progress=False)
    stream = tmp_path / "run.episodes.jsonl"
    evaluate("random", episodes=2, seed=7, env_kwargs=kwargs, progress=False,
             stream=str(stream))
    with open(stream, "a") as f:
        f.write('{"seed": 9, "start_po')          # a write torn by the interruption
    resumed = evaluate("random", episodes=4, seed=7, env_kwargs=kwargs, progress=False,
                       stream=str(stream), resume=True)
    assert _without_wall_time(resumed) == _without_wall_time(full)
    with pytest.raises(ValueError, match="other settings"):
        evaluate("oracle", episodes=4, seed=7, env_kwargs=kwargs, progress=False,
                 stream=str(stream), resume=True)


def test_homing_eval_refuses_an_unwritable_out_before_running(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(SystemExit) as exit_:
        eval_cli.main(["--policy", "random", "--episodes", "50", "--quiet",
                       "--out", str(blocker / "sub" / "r.json")])
    assert exit_.value.code == 2
    assert re.search("cannot write|is a file, not a folder", capsys.readouterr().err)


@pytest.mark.slow
def test_ray_backend_gives_the_records_of_the_local_pool():
    pytest.importorskip("ray")
    import dataclasses

    import ray

    from homing_train.harness.evaluate import evaluate

    kwargs = {"panorama_shape": [16, 64], "max_episode_steps": 40}
    try:
        runs = [evaluate("random", episodes=3, seed=5, env_kwargs=kwargs, workers=2,
                         progress=False, backend=backend) for backend in ("local", "ray")]
        with pytest.raises(ValueError, match="unknown scene 'nowhere'"):
            evaluate("random", episodes=2, env_kwargs={"scene": "nowhere"}, workers=2,
                     progress=False, backend="ray")
    finally:
        ray.shutdown()

    def strip(r):
        return [{k: v for k, v in dataclasses.asdict(e).items() if k != "wall_time"}
                for e in r.episodes]
    assert strip(runs[0]) == strip(runs[1]) and len(runs[1].episodes) == 3


def test_route_shortest_path_visits_every_target(make_env, controller_for):
    """On a route, SPL's shortest path runs start -> target 1 -> ... -> last target (here
    straight legs in the open hallway: their summed lengths)."""
    route = [(1.0, 0.0), (1.6, 0.3), (2.2, -0.2), (2.8, 0.3)]
    env = make_env("homing_gym/RouteFollowing-v0", route=route, start_jitter=(0.0, 0.0),
                   success_on="stop", max_episode_steps=300)
    record = run_episode(env, controller_for("oracle", env), seed=0)
    legs = sum(math.dist(a, b) for a, b in zip(route[:-1], route[1:]))
    assert record.success
    assert abs(record.shortest_path - legs) < 0.01
    assert record.spl > 0.85


@pytest.mark.parametrize("scene", ["random_nature", "random_rooms"])
def test_the_oracle_follows_random_routes_to_their_last_target(make_env, controller_for,
                                                               scene):
    env = make_env("homing_gym/RouteFollowing-v0", scene=scene, route="random", n_targets=8,
                   panorama_shape=(16, 64))
    record = run_episode(env, controller_for("oracle", env), seed=5)
    assert record.success and record.collisions == 0
    assert record.targets_finished == 8 and max(record.target_errors) < 0.1
    assert record.spl > 0.85


def test_compare_notes_say_which_rows_differ_in_renderer_and_settings():
    from homing_train.harness.compare import settings_notes

    def result(policy, **kwargs):
        return EvalResult(policy, {}, "homing_gym/LocalHoming-v0", kwargs, 0, [],
                          summary={"episodes": 0})

    same = {"renderer": "raycast", "physics_substeps": 12}
    rows = [result("oracle", **same, obs_keys=["panorama"]),
            result("distance", **same, obs_keys=["panorama", "goal_step"]),
            result("ppo", renderer="tiny", physics_substeps=24, panorama_shape=[32, 128])]
    notes = settings_notes(rows)
    assert notes[0] == "rows differ in renderer: raycast (oracle, distance); tiny (ppo)"
    assert notes[1] == ("ppo runs with other env settings: panorama_shape=[32, 128], "
                        "physics_substeps=24, renderer='tiny'")
    assert settings_notes(rows[:2]) == []          # obs_keys change no episode
    slow = result("ppo", **same, control_period=0.2, max_episode_steps=200)
    assert settings_notes(rows[:2] + [slow])[0] == (
        "rows differ in time per episode: 50 s (oracle, distance); 40 s (ppo)")
    same_time = result("ppo", **same, control_period=0.2, max_episode_steps=250)
    assert not any("time" in n for n in settings_notes(rows[:2] + [same_time]))


def test_a_ray_address_where_nothing_answers_fails_at_once():
    import socket

    from homing_train.harness.evaluate import check_ray_address
    with socket.socket() as s:                     # a port that was free a moment ago
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    with pytest.raises(ValueError, match=f"127.0.0.1:{port}'. nothing answers there"):
        check_ray_address(f"127.0.0.1:{port}", timeout=2.0)
    with pytest.raises(ValueError, match="expected HOST:PORT"):
        check_ray_address("localhost")
    check_ray_address("auto")                      # left to Ray
    with socket.socket() as server:                # something that accepts, and is silent
        server.bind(("127.0.0.1", 0))
        server.listen()
        with pytest.raises(ValueError, match="not as Ray does .* it said nothing"):
            check_ray_address(f"ray://127.0.0.1:{server.getsockname()[1]}", timeout=1.0)


def test_an_episode_that_passes_home_and_drives_on_is_measured_from_its_path():
    # straight along y = 0.9 in the arena (clear of the cylinders): through home at
    # x = -0.3 and on for 40 steps of 0.1 s at 0.3 m/s
    from homing_train.harness import metrics
    from homing_train.harness.evaluate import run_episode

    class Forward:
        def predict(self, observation, state=None, episode_start=None, deterministic=True):
            return np.array([1.0, 0.0], np.float32), state

    env = gym.make(ENV_ID, panorama_shape=(16, 64), max_episode_steps=40, success_on="stop")
    start, home = (-0.9, 0.9, 0.0), (-0.3, 0.9, 0.0)
    record = run_episode(env, Forward(), 0, start=start, home=home)
    env.close()
    path = np.asarray(record.trajectory)
    distances = np.hypot(path[:, 0] - home[0], path[:, 1] - home[1])
    assert record.min_distance == pytest.approx(distances.min(), abs=1e-3) and \
        record.min_distance < 0.05
    assert record.final_distance == pytest.approx(distances[-1], abs=1e-3)
    assert record.final_distance > 0.3
    assert not record.success and record.shortest_path == pytest.approx(0.6, abs=0.02)
    # soft-SPL from where it ended, not from its closest approach
    assert record.soft_spl == pytest.approx(metrics.soft_spl(
        record.final_distance, record.shortest_path, record.path_length), abs=0.02)
    assert record.soft_spl < 0.5 * record.shortest_path / record.path_length


def test_harness_passes_its_defaults_only_to_envs_that_take_them():
    """A user's env whose constructor names its arguments gets the harness's recorded
    settings only where it takes them, and a given argument it does not take is an
    error naming it (not a TypeError from deep inside gym.make)."""
    from homing_gym.envs import LocalHomingEnv
    from homing_train.harness.evaluate import env_parameters, harness_env_kwargs

    class FixedEnv(LocalHomingEnv):
        def __init__(self, render_mode=None, renderer="tiny", size=1.0):
            super().__init__(render_mode=render_mode, renderer=renderer)

    gym.register("test_harness/FixedEnv-v0", entry_point=FixedEnv)
    try:
        assert env_parameters("test_harness/FixedEnv-v0") == {"render_mode", "renderer", "size"}
        added = {"renderer": "raycast", "physics_substeps": 12, "obs_keys": ["panorama"]}
        assert harness_env_kwargs("test_harness/FixedEnv-v0", {"size": 2.0}, added) == {
            "renderer": "raycast", "size": 2.0}
        with pytest.raises(ValueError, match=r"does not take the arguments \['bogus'\]; "
                                             r"it takes \['renderer', 'size'\]"):
            harness_env_kwargs("test_harness/FixedEnv-v0", {"bogus": 1}, added)
    finally:
        gym.registry.pop("test_harness/FixedEnv-v0")
    # homing-gym's own envs take any name and check it themselves: everything is passed
    assert env_parameters("homing_gym/LocalHoming-v0") is None
    assert harness_env_kwargs("homing_gym/LocalHoming-v0", {"scene": "lab"}, added) == {
        **added, "scene": "lab"}


def test_field_grid_keeps_only_points_with_a_path_home():
    from homing_gym.scenes.base import Scene, Wall

    # 6 x 2 m split at x = 0 by a wall from bound to bound: the right room has no way home
    scene = Scene("two_rooms", ((-3.0, -1.0), (3.0, 1.0)),
                  walls=(Wall((0.0, -1.0), (0.0, 1.0), thickness=0.1),))
    points = field_cli.grid_points(scene, (-1.5, 0.0, 0.0), 0.25, 0.22, 0.15, 0.22)
    assert len(points) > 10
    assert np.all(points[:, 0] < 0)
