"""homing-train under faults: torn checkpoints, saves cut by a full disk, a reused or busy
run folder, a bad config.yml on --resume, bad policy_kwargs."""

import errno
import json
import shutil

import pytest
import torch
import yaml

from homing_train.learning.checkpoints import save_model
from homing_train.learning.train import latest_checkpoint, main
from homing_gym.outputs import OutputLock

# a tiny run: 36x64 panoramas, one env, a rollout of 64 steps, checkpoints every 128
TINY = ["--env-kwargs", json.dumps({"panorama_shape": [36, 64], "max_episode_steps": 16}),
        "--n-envs", "1", "--vec", "dummy", "--no-progress",
        "--hp", "n_steps=64", "--hp", "batch_size=32", "--hp", "n_epochs=1",
        "--hp", "eval_freq=128", "--hp", "eval_episodes=1", "--hp", "checkpoint_freq=128",
        "--hp", "features_dim=32"]


def weights(path):
    """The policy weights saved in a model zip, read as plain tensors."""
    from homing_train.learning.policy_zip import load_policy

    return load_policy(path).policy.state_dict()


def same_weights(a, b) -> bool:
    return a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a)


def error_line(capsys) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return err.strip().splitlines()[-1]


def test_resume_skips_a_torn_newest_checkpoint_and_continues_as_from_the_intact_one(
        tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["--timesteps", "256", "--out", str(run), *TINY]) == 0
    torn = run / "checkpoints" / "ppo_256_steps.zip"
    clean = tmp_path / "clean"
    shutil.copytree(run, clean)
    (clean / "checkpoints" / "ppo_256_steps.zip").unlink()     # as if never saved
    data = torn.read_bytes()
    torn.write_bytes(data[:len(data) // 2])                      # a save cut by a kill
    assert latest_checkpoint(run).name == "ppo_128_steps.zip"
    capsys.readouterr()
    assert main(["--resume", str(run), "--timesteps", "384", "--no-progress"]) == 0
    err = capsys.readouterr().err
    warnings = [line for line in err.splitlines() if "warning" in line]
    assert len(warnings) == 1 and "torn checkpoint" in warnings[0]
    assert "ppo_256_steps.zip" in warnings[0]
    assert latest_checkpoint(run).name == "ppo_384_steps.zip"
    assert main(["--resume", str(clean), "--timesteps", "384", "--no-progress"]) == 0
    assert same_weights(weights(run / "model.zip"), weights(clean / "model.zip"))
    summary = json.loads((run / "summary.json").read_text())
    assert [(s["from_step"], s["to_step"]) for s in summary["sessions"]] == [(0, 256),
                                                                            (128, 384)]


def test_resume_with_every_checkpoint_torn_is_one_clear_error(tmp_path, capsys):
    run = tmp_path / "run"
    main(["--timesteps", "128", "--out", str(run), *TINY])
    checkpoint = run / "checkpoints" / "ppo_128_steps.zip"
    checkpoint.write_bytes(b"PK\x03\x04 cut short")
    model = (run / "model.zip").read_bytes()
    capsys.readouterr()
    with pytest.raises(SystemExit) as exit_:
        main(["--resume", str(run), "--timesteps", "256", "--no-progress"])
    assert exit_.value.code == 2
    assert "no intact checkpoint in" in error_line(capsys)
    assert (run / "model.zip").read_bytes() == model


def test_a_save_cut_by_a_full_disk_keeps_the_old_file_and_leaves_no_temporary(
        tmp_path, monkeypatch, capsys):
    from stable_baselines3 import PPO

    run = tmp_path / "run"
    main(["--timesteps", "128", "--out", str(run), *TINY])
    kept = {p.name: p.read_bytes() for p in (run / "checkpoints").iterdir()}
    model = (run / "model.zip").read_bytes()
    real_save = torch.save

    def save_then_fill_the_disk(obj, f, *args, **kwargs):
        real_save(obj, f, *args, **kwargs)
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(torch, "save", save_then_fill_the_disk)
    with pytest.raises(OSError, match="No space left"):        # an overwrite cut short
        save_model(PPO.load(run / "model.zip"), run / "model.zip")
    assert (run / "model.zip").read_bytes() == model
    with pytest.raises(SystemExit) as exit_:        # the first save of the resumed run fails
        main(["--resume", str(run), "--timesteps", "384", "--no-progress"])
    assert exit_.value.code == 1
    line = error_line(capsys)
    assert "No space left on device" in line and "continues from ppo_128_steps.zip" in line
    assert {p.name: p.read_bytes() for p in (run / "checkpoints").iterdir()} == kept
    assert (run / "model.zip").read_bytes() == model
    assert not [p for p in run.rglob("*") if p.name.startswith(".")]     # no temporaries
    monkeypatch.setattr(torch, "save", real_save)
    assert main(["--resume", str(run), "--timesteps", "256", "--no-progress"]) == 0


def test_out_of_an_existing_run_is_refused_and_an_empty_folder_is_taken(tmp_path, capsys):
    run = tmp_path / "run"
    main(["--timesteps", "64", "--out", str(run), *TINY])
    before = {p: p.read_bytes() for p in run.rglob("*") if p.is_file()}
    capsys.readouterr()
    with pytest.raises(SystemExit) as exit_:
        main(["--timesteps", "64", "--out", str(run), *TINY])
    assert exit_.value.code == 2
    line = error_line(capsys)
    assert str(run) in line and f"--resume {run}" in line and "another --out" in line
    assert {p: p.read_bytes() for p in run.rglob("*") if p.is_file()} == before
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["--timesteps", "64", "--out", str(empty), *TINY]) == 0


def test_a_second_homing_train_on_a_busy_run_folder_is_refused(tmp_path, capsys):
    run = tmp_path / "run"
    run.mkdir()
    (run / "config.yml").write_text(yaml.safe_dump({"env_id": "homing_gym/LocalHoming-v0"}))
    with OutputLock(run):                  # another homing-train holds it
        for argv in (["--timesteps", "64", "--out", str(run), *TINY],
                     ["--resume", str(run), "--no-progress"]):
            with pytest.raises(SystemExit) as exit_:
                main(argv)
            assert exit_.value.code == 2
            assert "being written by another run" in error_line(capsys)
    assert [p.name for p in run.iterdir()] == ["config.yml"]


@pytest.mark.parametrize("argv, message", [
    (["--resume", "{tmp}"], "no config.yml there (not a run folder)"),
    (["--resume", "{tmp}/nowhere"], "no config.yml there (not a run folder)"),
    (["--resume", "{tmp}", "--out", "{tmp}/other"], "--out is not used with it"),
    (["--out", ""], "expected a folder path, got an empty one"),
    (["--out", "/dev/null"], "is a file; expected a folder"),
    (["--hp", "policy_kwargs={net_arch: [8], nope: 1}", "--out", "{tmp}/run"],
     "unknown policy_kwargs ['nope']; allowed: ['net_arch',"),
    ([*TINY, "--hp", "policy_kwargs={net_arch: [1000000000]}", "--out", "{tmp}/run"],
     "64000000000 parameters x 16 bytes) would take 953.7 GiB, more than this machine's"),
    ([*TINY, "--hp", "n_steps=1000000000", "--out", "{tmp}/run"],
     "(n_steps 1000000000 x n_envs 1 x 13824 observation values x 4 bytes) would take"),
    ([*TINY, "--n-envs", "2000", "--vec", "subproc", "--out", "{tmp}/run"],
     "2000 env worker processes (--vec subproc, about 300 MiB each) would take 585.9 GiB"),
])
def test_bad_run_folders_and_settings_are_one_clear_error(tmp_path, capsys, argv, message):
    with pytest.raises(SystemExit) as exit_:
        main([a.replace("{tmp}", str(tmp_path)) for a in argv])
    assert exit_.value.code == 2
    assert message in error_line(capsys)
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("text, message", [
    ("default: {policy_kwargs: {net_arch: [8], nope: 1}}",
     "unknown policy_kwargs ['nope']; allowed: ['net_arch',"),
    ("homing_gym/LocalHoming-v0: [n_steps, 64]", "'homing_gym/LocalHoming-v0' must map "
                                                 "setting names to values, got ['n_steps', 64]"),
    ("default: {n_steps: [unclosed", "cannot read hyperparameter file"),
])
def test_a_bad_hyperparameter_file_is_one_clear_error(tmp_path, capsys, text, message):
    (tmp_path / "ppo.yml").write_text(text)
    with pytest.raises(SystemExit) as exit_:
        main(["--hyperparams", str(tmp_path / "ppo.yml"), "--out", str(tmp_path / "run")])
    assert exit_.value.code == 2
    assert message in error_line(capsys)
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("text, message", [
    ("env_id: [unclosed", "config.yml is not readable YAML"),
    ("- homing_gym/LocalHoming-v0\n", "config.yml must map the run's settings"),
    ("env_id: homing_gym/LocalHoming-v0\nbogus: 1\n", "unknown fields ['bogus']"),
    ("seed: 3\n", "config.yml: no env_id field"),
    ("env_id: homing_gym/LocalHoming-v0\nn_envs: two\n", "n_envs must be an integer >= 1"),
    ("env_id: homing_gym/LocalHoming-v0\nfeatures_dim: true\n",
     "features_dim must be an integer >= 1"),
    ("env_id: homing_gym/LocalHoming-v0\nenv_kwargs: [1]\n", "env_kwargs must be a mapping"),
    ("env_id: homing_gym/LocalHoming-v0\nppo: {policy_kwargs: {nope: 1}}\n",
     "unknown policy_kwargs ['nope']"),
    ("env_id: !!python/object/apply:os.system ['touch {tmp}/ran']\n",
     "config.yml is not readable YAML"),
])
def test_a_bad_config_yml_on_resume_names_the_file_and_the_field(tmp_path, capsys, text,
                                                                   message):
    (tmp_path / "config.yml").write_text(text.replace("{tmp}", str(tmp_path)))
    with pytest.raises(SystemExit) as exit_:
        main(["--resume", str(tmp_path), "--no-progress"])
    assert exit_.value.code == 2
    line = error_line(capsys)
    assert message in line and str(tmp_path / "config.yml") in line
    assert not (tmp_path / "ran").exists()


KILLED_MID_SAVE = """
import os, signal, sys, torch
from homing_train.learning.train import main
real_save, checkpoints = torch.save, os.path.join(sys.argv[1], "checkpoints")
def save_then_die(obj, f, *args, **kwargs):    # SIGKILL inside the save of ppo_256
    real_save(obj, f, *args, **kwargs)
    if any(n.startswith(".ppo_256_steps.zip.") for n in os.listdir(checkpoints)):
        os.kill(os.getpid(), signal.SIGKILL)
torch.save = save_then_die
main(["--timesteps", "256", "--out", sys.argv[1], *sys.argv[2:]])
"""


def test_a_run_killed_mid_save_resumes_from_its_last_whole_checkpoint(tmp_path, capsys):
    import subprocess
    import sys

    run = tmp_path / "run"
    killed = subprocess.run([sys.executable, "-c", KILLED_MID_SAVE, str(run), *TINY],
                            capture_output=True, text=True, timeout=300)
    assert killed.returncode == -9, killed.stderr
    assert sorted(p.name for p in (run / "checkpoints").iterdir() if not p.name.startswith(
        ".")) == ["ppo_128_steps.zip"]
    assert [p for p in (run / "checkpoints").iterdir() if p.name.endswith(".tmp")]
    assert main(["--resume", str(run), "--timesteps", "256", "--no-progress"]) == 0
    assert "warning" not in capsys.readouterr().err
    assert latest_checkpoint(run).name == "ppo_256_steps.zip"
    assert not [p for p in run.rglob("*.tmp")]


def test_ctrl_c_in_the_final_save_keeps_the_old_model_and_says_how_to_resume(
        tmp_path, monkeypatch, capsys):
    from homing_train.learning import checkpoints

    run = tmp_path / "run"
    main(["--timesteps", "128", "--out", str(run), *TINY])
    model = (run / "model.zip").read_bytes()
    real_save = checkpoints.save_model

    def interrupted_at_model_zip(model, path):
        if path.name == "model.zip":
            with checkpoints.atomic_path(str(path)) as tmp:
                open(tmp, "wb").write(b"PK half a zip")
                raise KeyboardInterrupt
        real_save(model, path)

    monkeypatch.setattr(checkpoints, "save_model", interrupted_at_model_zip)
    capsys.readouterr()
    with pytest.raises(SystemExit) as exit_:
        main(["--resume", str(run), "--timesteps", "256", "--no-progress"])
    assert exit_.value.code == 130
    assert error_line(capsys).endswith("continues from ppo_256_steps.zip")
    assert (run / "model.zip").read_bytes() == model
    assert not list(run.glob(".*.tmp"))
