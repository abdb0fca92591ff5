"""Evaluation settings recorded beside a policy zip."""

import yaml

import pytest

from homing_train.harness.policies import (DEFAULT_POLICY, POLICY_DIR, PolicySpec, policy_spec,
                                           recorded_settings)


def test_a_run_folders_models_and_checkpoints_take_the_runs_training_settings(tmp_path):
    run = tmp_path / "run"
    (run / "checkpoints").mkdir(parents=True)
    (run / "config.yml").write_text(yaml.safe_dump({
        "env_id": "homing_gym/LocalHoming-v0",
        "env_kwargs": {"scene": ["random_rooms"], "panorama_shape": [16, 128]}}))
    for zip_path in (run / "best_model.zip", run / "checkpoints" / "ppo_50000_steps.zip"):
        settings = recorded_settings(str(zip_path))
        assert settings.env_id == "homing_gym/LocalHoming-v0"
        # the training scene is dropped: the evaluation's own scene applies
        assert settings.env_kwargs == {"panorama_shape": [16, 128]}
        assert settings.params == {}
    config = yaml.safe_load((run / "config.yml").read_text())
    (run / "config.yml").write_text(yaml.safe_dump({**config, "eval_deterministic": False}))
    assert recorded_settings(str(run / "best_model.zip")).params == {"deterministic": False}
    assert recorded_settings(str(tmp_path / "elsewhere.zip")).env_kwargs == {}


@pytest.mark.parametrize("path, label", [
    ("runs/abc/model.zip", "abc/model"), ("runs/abc/best_model.zip", "abc/best_model"),
    ("runs/abc/checkpoints/ppo_8_steps.zip", "abc/ppo_8_steps"),
    ("train/shipped/ppo_procedural_long.zip", "ppo_procedural_long"), ("model.zip", "model")])
def test_a_models_label_names_its_run_where_the_file_name_is_every_runs(path, label):
    assert PolicySpec("sb3", path).label == label


def test_ppo_and_shipped_names_are_policies():
    assert policy_spec("ppo").source == str(POLICY_DIR / f"{DEFAULT_POLICY}.zip")
    assert policy_spec("ppo_procedural_imitation").kind == "sb3"
    assert policy_spec("ppo", {"deterministic": False}).params == {"deterministic": False}
    with pytest.raises(ValueError, match=r"unknown policy 'ppo_localhoming'.*a shipped policy "
                       r"\['ppo', 'ppo_procedural_imitation', 'ppo_procedural_long'\]"):
        policy_spec("ppo_localhoming")


def test_ppo_is_the_default_policy_in_the_suite_and_in_a_protocol_cell(tmp_path, capsys):
    from homing_train.harness import suite
    from homing_train.harness.matrix import run_cell
    from homing_train.harness.protocols import protocol

    assert suite.main(["--scene", "arena", "--methods", "ppo", "--episodes", "1", "--workers",
                       "1", "--out", str(tmp_path / "suite")]) == 0
    assert (tmp_path / "suite" / f"{DEFAULT_POLICY}.json").exists()
    cell = run_cell(protocol("yukim"), "ppo", tmp_path / "cell", episodes=1, progress=False)
    assert cell.method == DEFAULT_POLICY and f"--policy {DEFAULT_POLICY}" in cell.command
