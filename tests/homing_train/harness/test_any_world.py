"""Every command takes any world: homing-suite's --env-kwargs/--scene reach every row
(learned rows with the controllers' time), homing-field and homing-demo take the same
options, and a protocol's episodes can be drawn from another seed, recorded as not the
canonical draw."""

import json

import gymnasium as gym
import pytest

import homing_gym  # noqa: F401

from homing_train.harness import demo, eval_command, field, suite
from homing_train.harness.matrix import Cell, matrix_markdown
from homing_train.harness.policies import shipped_policies
from homing_train.harness.protocols import protocol


def test_a_reseeded_protocol_is_not_the_canonical_draw():
    yukim = protocol("yukim")
    assert yukim.canonical and yukim.reseeded(yukim.seed).canonical
    other = yukim.reseeded(5)
    assert not other.canonical and other.seed == 5 and other.canonical_seed == yukim.seed
    assert other.reseeded(yukim.seed).canonical                # back to its own draw
    assert other.command("oracle") == \
        "homing-eval --protocol yukim --policy oracle --seed 5 --out OUT.json"
    assert "not the canonical draw" in other.label and "not" not in yukim.label
    assert other.settings[0].episode_tasks(4, other.seed) != \
        yukim.settings[0].episode_tasks(4, yukim.seed)


def test_eval_protocol_with_a_seed_records_that_it_is_not_the_canonical_draw(tmp_path,
                                                                             capsys):
    out = tmp_path / "cell.json"
    assert eval_command.main(["--protocol", "yukim", "--policy", "oracle", "--episodes", "4",
                              "--seed", "5", "--quiet", "--out", str(out)]) == 0
    assert "(seed 5: not the canonical draw, seed 0)" in capsys.readouterr().out
    doc = json.loads(out.read_text())
    assert doc["canonical_draw"] is False and doc["seed"] == 5
    assert doc["command"].endswith("--episodes 4 --seed 5 --out OUT.json")
    assert json.loads((tmp_path / "cell" / "cell.json").read_text()) == doc
    (setting,) = [p for p in (tmp_path / "cell").glob("*.json") if p.name != "cell.json"]
    seeds = [e["seed"] for e in json.loads(setting.read_text())["episodes"]]
    assert seeds == [5, 1005, 2005, 3005]                      # canonical: 0, 1000, ...
    table = matrix_markdown([Cell(**doc)])
    assert "Not the canonical draw of episodes: yukim (seed 5)." in table
    assert "canonical" not in matrix_markdown([Cell(**{**doc, "seed": 0,
                                                       "canonical_draw": True})])


def test_suite_env_kwargs_reach_every_row(tmp_path):
    env = gym.make("homing_gym/LocalHoming-v0", scene="hallway")
    hallway_home = env.reset(seed=0)[1]["home_pose"]          # episode 0 in the hallway
    env.close()
    out = tmp_path / "suite"
    assert suite.main(["--methods", "random", "oracle", "--episodes", "2", "--workers", "1",
                       "--scene", "hallway", "--env-kwargs", '{"max_episode_steps": 6}',
                       "--out", str(out)]) == 0
    for method in ("random", "oracle"):
        doc = json.loads((out / f"{method}.json").read_text())
        assert doc["env_kwargs"]["scene"] == "hallway"
        assert doc["env_kwargs"]["success_on"] == "stop"
        assert doc["env_kwargs"]["max_episode_steps"] == 6
        assert doc["episodes"][0]["home_pose"] == pytest.approx(hallway_home, abs=1e-4)
    random_walk = json.loads((out / "random.json").read_text())
    assert [e["steps"] for e in random_walk["episodes"]] == [6, 6]     # it never stops


def test_a_learned_row_gets_the_suites_world_and_the_same_time(tmp_path):
    period = {name: p.env_kwargs.get("control_period", 0.1)
              for name, p in shipped_policies().items()}
    slower = sorted(name for name, seconds in period.items() if seconds == 0.2)
    if not slower:
        pytest.skip("no shipped policy with a 0.2 s control period")
    out = tmp_path / "suite"
    assert suite.main(["--methods", "oracle", slower[0], "--episodes", "1", "--workers", "1",
                       "--scene", "hallway", "--env-kwargs", '{"max_episode_steps": 6}',
                       "--out", str(out)]) == 0
    learned = json.loads((out / f"{slower[0]}.json").read_text())
    assert learned["env_kwargs"]["scene"] == "hallway"
    assert learned["env_kwargs"]["max_episode_steps"] == 3         # 6 x 0.1 s = 3 x 0.2 s
    assert "time per episode" not in (out / "table.md").read_text()


@pytest.mark.parametrize("argv, message", [
    (["--env-kwargs", '{"success_on": "reach"}'], "--success-on"),
    (["--scene", "moon"], "unknown scene 'moon'"),
    (["--scene", "lab", "--env-kwargs", '{"scene": "arena"}'], "give the scene once"),
    (["--protocols", "yukim", "--scene", "lab"], "--protocols fix the envs"),
])
def test_suite_refuses_bad_world_options_before_any_work(tmp_path, capsys, argv, message):
    with pytest.raises(SystemExit) as err:
        suite.main([*argv, "--episodes", "1", "--out", str(tmp_path / "suite")])
    assert err.value.code == 2 and message in capsys.readouterr().err
    assert not (tmp_path / "suite").exists()


def test_field_and_demo_take_the_world_options(tmp_path, capsys):
    png = tmp_path / "field.png"
    assert field.main(["--policy", "oracle", "--scene", "hallway", "--env-kwargs",
                       '{"max_episode_steps": 5}', "--grid", "0.9", "--no-return", "--quiet",
                       "--out", str(png)]) == 0
    doc = json.loads(png.with_suffix(".json").read_text())
    assert doc["env_kwargs"] == {"scene": "hallway", "max_episode_steps": 5}
    assert max(x for x, _, _ in doc["points"]) > 2.0             # the 8 m hallway
    assert demo.main(["--env", "homing_gym/RouteFollowing-v0", "--scene", "hallway",
                      "--env-kwargs", '{"n_targets": 2, "max_episode_steps": 3}', "--seed", "0",
                      "--out", str(tmp_path / "demo")]) == 0
    assert "in 3 steps" in capsys.readouterr().out
    assert sorted(p.name for p in (tmp_path / "demo").iterdir()) == \
        ["demo.gif", "demo.png", "views.png"]
    with pytest.raises(SystemExit) as err:
        demo.main(["--env-kwargs", '{"bogus": 1}', "--out", str(tmp_path / "bad")])
    assert err.value.code == 2 and "bogus" in capsys.readouterr().err
