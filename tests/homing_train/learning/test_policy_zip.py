"""Policy zips are read without unpickling (homing_train.learning.policy_zip)."""

import base64
import json
import pickle
import zipfile

import numpy as np
import pytest
import torch

from homing_train.harness.policies import policy_spec
from homing_train.harness.policies import POLICY_DIR
from homing_train.learning.policy_zip import UntrustedPolicyError, load_policy

SHIPPED = POLICY_DIR / "ppo_procedural_long.zip"


class _Payload:
    """Unpickling this creates the file ``marker``: what a hostile zip could do."""

    def __init__(self, marker: str):
        self.marker = marker

    def __reduce__(self):
        return (open, (self.marker, "w"))


def _zip_with(tmp_path, edit) -> str:
    """A copy of the shipped zip whose ``data`` JSON went through ``edit``."""
    out = tmp_path / "edited.zip"
    with zipfile.ZipFile(SHIPPED) as src, zipfile.ZipFile(out, "w") as dst:
        for item in src.infolist():
            payload = src.read(item.filename)
            if item.filename == "data":
                doc = json.loads(payload)
                edit(doc)
                payload = json.dumps(doc).encode()
            dst.writestr(item, payload)
    return str(out)


def test_shipped_policy_loads_without_unpickling_and_keeps_its_weights():
    loaded = load_policy(SHIPPED)
    assert loaded.observation_space["panorama"].shape == (3, 16, 64)
    assert loaded.action_space.n == 4
    with zipfile.ZipFile(SHIPPED) as archive:
        import io
        saved = torch.load(io.BytesIO(archive.read("policy.pth")), weights_only=True)
    state = loaded.policy.state_dict()
    assert set(state) == set(saved)
    assert all(torch.equal(state[k], saved[k]) for k in saved)
    obs = {k: np.zeros((16, 64, 3), np.uint8) for k in ("panorama", "goal")}
    action, _ = loaded.predict(obs, deterministic=True)
    assert int(action) in range(4)


def test_a_pickled_payload_is_refused_and_nothing_runs(tmp_path):
    marker = tmp_path / "ran.txt"

    def plant(doc):
        doc["policy_kwargs"]["features_extractor_class"] = "<class 'evil.Payload'>"
        doc["policy_kwargs"][":serialized:"] = base64.b64encode(
            pickle.dumps({"features_extractor_class": _Payload(str(marker))})).decode()

    hostile = _zip_with(tmp_path, plant)
    with pytest.raises(UntrustedPolicyError, match="evil.Payload.*--trust-policy"):
        load_policy(hostile)
    with pytest.raises(ValueError, match="trust"):
        policy_spec(hostile).build()
    assert not marker.exists()
    # the danger is real: the trusting loader runs the payload
    with pytest.raises(Exception):
        load_policy(hostile, trust=True)
    assert marker.exists()


def test_unknown_policy_class_and_broken_files_are_clear_errors(tmp_path):
    def other_class(doc):
        doc["policy_class"]["__doc__"] = "something else"

    with pytest.raises(UntrustedPolicyError, match="policy class"):
        load_policy(_zip_with(tmp_path, other_class))
    broken = tmp_path / "broken.zip"
    broken.write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="not a stable-baselines3 model zip"):
        load_policy(broken)
    with pytest.raises(ValueError, match="does not exist"):
        load_policy(tmp_path / "missing.zip")
