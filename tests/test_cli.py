"""Every command has the same shape: named prog, defaults in --help, main(argv) -> int."""

import importlib

import pytest

from homing_gym.cli import plain

COMMANDS = {
    "homing-eval": "homing_train.harness.eval_command",
    "homing-compare": "homing_train.harness.compare",
    "homing-field": "homing_train.harness.field",
    "homing-suite": "homing_train.harness.suite",
    "homing-demo": "homing_train.harness.demo",
    "homing-train": "homing_train.learning.train",
    "homing-benchmark": "homing_gym.benchmark",
    "python -m homing_train.figures.hong": "homing_train.figures.hong",
    "python -m homing_train.figures.yukim": "homing_train.figures.yukim",
    "python -m homing_train.figures.bearing": "homing_train.figures.bearing",
    "python -m homing_train.figures.selfsimilar": "homing_train.figures.selfsimilar",
    "python -m homing_train.figures.multires": "homing_train.figures.multires",
    "python -m homing_train.figures.renderers": "homing_train.figures.renderers",
    "python -m homing_train.figures.generalisation": "homing_train.figures.generalisation",
    "python -m homing_train.figures.checkpoints": "homing_train.figures.checkpoints",
    "python -m homing_train.learning.ship": "homing_train.learning.ship",
    "python -m homing_train.learning.rllib_ppo": "homing_train.learning.rllib_ppo",
    "python -m homing_train.learning.saturation": "homing_train.learning.saturation",
    "python -m homing_gym.envcard": "homing_gym.envcard",
    "python -m homing_gym.scenes.textures": "homing_gym.scenes.textures",
    "python -m homing_gym.scenes.mesh_example": "homing_gym.scenes.mesh_example",
    "python -m homing_gym.scenes.tussocks": "homing_gym.scenes.tussocks",
    "python -m homing_gym.freespace": "homing_gym.freespace",
    "python -m homing_gym.memory_check": "homing_gym.memory_check",
}


@pytest.mark.parametrize("prog", sorted(COMMANDS))
def test_help_names_the_command_and_shows_defaults(prog, capsys):
    module = importlib.import_module(COMMANDS[prog])
    with pytest.raises(SystemExit) as exit_:
        module.main(["--help"])
    assert exit_.value.code == 0
    text = capsys.readouterr().out
    assert text.startswith(f"usage: {prog}")
    assert "``" not in text and ":mod:" not in text
    if "--seed" in text:
        assert "(default: " in text


def test_plain_drops_rest_markup():
    assert plain("see :mod:`homing_gym.env` and ``x = 1``, :func:`~a.b.c`") == \
        "see homing_gym.env and x = 1, c"


@pytest.mark.slow
def test_import_makes_a_user_scene_visible_to_the_command_and_its_workers(tmp_path):
    import os
    import subprocess
    import sys

    (tmp_path / "my_world.py").write_text(
        "from homing_gym.scenes import Landmark, Scene, SceneFactory, register_scene, "
        "square_walls\n"
        "register_scene('two_poles', SceneFactory(lambda rng: Scene('two_poles', "
        "bounds=((-1.5, -1.5), (1.5, 1.5)), walls=square_walls(3.0), "
        "landmarks=(Landmark((0.5, 0.5), radius=0.05, height=1.0),))))\n")
    env = {**os.environ, "PYTHONPATH": str(tmp_path)}
    command = [sys.executable, "-m", "homing_train.harness.eval_command", "--policy", "oracle",
               "--episodes", "2", "--workers", "2", "--quiet", "--env-kwargs",
               '{"scene": "two_poles", "max_episode_steps": 5}', "--out",
               str(tmp_path / "r.json")]
    without = subprocess.run(command, capture_output=True, text=True, env=env, timeout=300)
    assert without.returncode == 2 and "unknown scene 'two_poles'" in without.stderr
    with_import = subprocess.run([*command, "--import", "my_world"], capture_output=True,
                                 text=True, env=env, timeout=300)
    assert with_import.returncode == 0, with_import.stderr[-2000:]
    assert "oracle on homing_gym/LocalHoming-v0: 2 episodes" in with_import.stdout


def test_textures_are_written_where_asked_and_match_the_shipped_ones(tmp_path):
    import cv2
    import numpy as np

    from homing_gym.scenes.textures import TEXTURE_DIR, main
    assert main(["--out", str(tmp_path)]) == 0
    written = sorted(path.name for path in tmp_path.iterdir())
    assert written == sorted(path.name for path in TEXTURE_DIR.glob("*.png"))
    for name in written:      # the pixels: the PNG encoder's bytes may vary by version
        assert np.array_equal(cv2.imread(str(tmp_path / name)),
                              cv2.imread(str(TEXTURE_DIR / name))), name


def test_import_finds_a_module_in_the_current_folder(tmp_path, monkeypatch):
    import sys

    from homing_gym.cli import import_user_module
    (tmp_path / "my_world_here.py").write_text("LOADED = True\n")
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p not in ("", str(tmp_path))])
    monkeypatch.setenv("HOMING_GYM_IMPORT", "")     # restored after: later subprocesses
    monkeypatch.setattr(sys, "modules", dict(sys.modules))   # must not import it
    import_user_module("my_world_here")
    assert sys.modules["my_world_here"].LOADED
    assert sys.path[-1] == str(tmp_path)                   # searched last: shadows nothing


@pytest.mark.parametrize("prog", ["homing-eval", "homing-suite", "homing-field", "homing-demo"])
def test_the_commands_that_run_episodes_take_the_same_world_options(prog, capsys):
    module = importlib.import_module(COMMANDS[prog])
    with pytest.raises(SystemExit):
        module.main(["--help"])
    text = capsys.readouterr().out
    for option in ("--env ENV", "--env-kwargs JSON", "--scene SCENE", "--import MODULE"):
        assert option in text, (prog, option)


def test_benchmark_runs_in_a_mesh_world_and_refuses_an_unknown_one(tmp_path, capsys):
    import json

    from homing_gym.benchmark import main
    from homing_gym.scenes.mesh_example import write_example_room

    write_example_room(tmp_path / "room.obj")
    world = f"mesh:{tmp_path / 'room.obj'}"
    out = tmp_path / "bench.json"
    assert main(["--worlds", world, "--renderers", "raycast", "--shapes", "48x256",
                 "--steps", "10", "--workers", "1", "--json", str(out)]) == 0
    (record,) = json.loads(out.read_text())
    assert record["config"] == f"raycast 48x256 {world}"
    assert record["env_kwargs"]["scene"] == world and record["env_steps_per_s"] > 0
    with pytest.raises(SystemExit) as err:
        main(["--worlds", "moon", "--steps", "10", "--json", str(tmp_path / "no.json")])
    assert err.value.code == 2
    assert "world 'moon': neither a benchmark world" in capsys.readouterr().err
    assert not (tmp_path / "no.json").exists()


def test_the_culling_bound_times_the_arena_first_and_refuses_no_poses(capsys):
    from homing_gym.benchmark import main

    assert main(["--culling-bound", "1", "--worlds", "grass10k"]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.startswith("| ")]
    cells = [row.strip("| ").split(" | ") for row in rows[1:]]
    assert [(c[0], c[1]) for c in cells] == [("arena", "1074"), ("grass10k", "10002")]
    assert all(0 < int(c[2]) < int(c[1]) for c in cells)       # some triangles shown
    with pytest.raises(SystemExit):
        main(["--culling-bound", "0"])
    assert "--culling-bound 0: need N >= 1 poses" in capsys.readouterr().err
