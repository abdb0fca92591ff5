"""Policy files from others: every size a zip declares is checked before anything is
allocated, every malformed field is one ValueError naming the file, the field and the
bound; ``--trust-policy`` loads zips pickled under the package's old name; a run folder's
``config.yml`` is read as checked plain YAML."""

import base64
import io
import json
import pickle
import subprocess
import sys
import types
import zipfile

import pytest
import torch
import yaml

from homing_train.harness.policies import POLICY_DIR, recorded_settings
from homing_train.learning import policy_zip
from homing_train.learning.policy_zip import (PolicyFileError, UntrustedPolicyError,
                                              load_policy)

SOURCE = POLICY_DIR / "ppo_procedural_long.zip"   # the smallest shipped zip
BIG_BOX = "Box(0, 255, (100000, 100000, 3), uint8)"   # 30 GB as the envs' uint8 images
SMALL_BOX = "Box(0, 255, (3, 16, 64), uint8)"


def crafted_zip(folder, name: str, edit=None, weights: bytes | None = None) -> str:
    """The shipped ``data`` and ``policy.pth`` of :data:`SOURCE` (the members the safe
    path reads), the data JSON through ``edit`` (a function changing it in place, or
    returning the new ``data`` bytes)."""
    with zipfile.ZipFile(SOURCE) as source:
        data, pth = source.read("data"), source.read("policy.pth")
    if edit is not None:
        doc = json.loads(data)
        data = edit(doc) or json.dumps(doc).encode()
    path = folder / name
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as out:
        out.writestr("data", data)
        out.writestr("policy.pth", pth if weights is None else weights)
    return str(path)


def setter(*keys: str, value):
    """An edit that sets ``data[keys[0]][keys[1]]... = value``."""
    def edit(doc):
        for key in keys[:-1]:
            doc = doc[key]
        doc[keys[-1]] = value
    return edit


def box_space(shape: str, dtype: str = "uint8") -> dict:
    return {":type:": "<class 'gymnasium.spaces.box.Box'>", "_shape": shape, "dtype": dtype,
            "low_repr": "0", "high_repr": "255"}


#: Memory bombs of the issue and their kin: (edit of the data JSON, what the error says).
BOMBS = {
    "dict_member": (setter("observation_space", "spaces",
                           value=f"{{'goal': {BIG_BOX}, 'panorama': {SMALL_BOX}}}"),
                    "observation_space [(100000, 100000, 3), (3, 16, 64)] takes "
                    "30,000,003,072 bytes a step, more than the 67,108,864 allowed"),
    "box_space": (setter("observation_space", value=box_space("(100000, 100000, 3)")),
                  "more than the 67,108,864 allowed"),
    "net_arch": (setter("policy_kwargs", "net_arch", value="[1000000000]"),
                 "more than the 100,000,000 allowed"),
    "wide_head": (setter("policy_kwargs", "features_extractor_kwargs",
                         value="{'features_dim': 1000000000}"),
                  "more than the 100,000,000 allowed"),
    "activations": (setter("policy_kwargs", "features_extractor_kwargs",
                           value="{'encoder': [[1000000, 1, 1]], 'head': [[1, 1, 64]]}"),
                    "values for one observation, more than the 100,000,000 allowed"),
    "actions": (setter("action_space", "n", value="1000000000000"),
                "action_space n must be an integer in [1, 65,536]"),
    "long_kwargs": (setter("policy_kwargs", "net_arch", value="[" + "64, " * 5000 + "]"),
                    "characters, more than the 4,096 allowed"),
    "deep_json": (lambda doc: b"[" * 200_000 + b"]" * 200_000, "nested deeper"),
}

BOMB_SCRIPT = """
import json, resource, sys
from homing_train.learning.policy_zip import load_policy
load_policy(sys.argv[1])           # everything imported and one network built
vms = int(open("/proc/self/statm").read().split()[0]) * resource.getpagesize()
resource.setrlimit(resource.RLIMIT_AS, (vms + 2 * 2**30, resource.RLIM_INFINITY))
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
messages = {}
for path in sys.argv[2:]:
    try:
        load_policy(path)
        messages[path] = "loaded"
    except Exception as err:
        messages[path] = f"{type(err).__name__}: {err}"
grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
print(json.dumps({"grown_kib": grown, "messages": messages}))
"""


def test_memory_bombs_are_refused_before_anything_is_allocated(tmp_path):
    """In a fresh interpreter held to 2 GiB more address space: each bomb is a
    PolicyFileError (or, for text that is not plain data, UntrustedPolicyError) naming the
    file and the bound, and the peak memory grows by under 64 MiB over all of them."""
    paths = {name: crafted_zip(tmp_path, f"{name}.zip", edit) for name, (edit, _) in
             BOMBS.items()}
    out = subprocess.run([sys.executable, "-c", BOMB_SCRIPT, str(SOURCE), *paths.values()],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    report = json.loads(out.stdout.strip().splitlines()[-1])
    for name, (_, expected) in BOMBS.items():
        message = report["messages"][paths[name]]
        assert message.startswith(f"PolicyFileError: {paths[name]}"), (name, message)
        assert expected in message, (name, message)
    assert report["grown_kib"] < 64 * 1024, report


def test_zip_directory_and_member_sizes_are_checked_before_reading(tmp_path, monkeypatch):
    many = tmp_path / "many.zip"
    with zipfile.ZipFile(many, "w") as out:
        for i in range(100):
            out.writestr(f"m{i}", b"")
    with pytest.raises(PolicyFileError, match=r"100 zip members, more than the 64 allowed"):
        load_policy(many)
    huge_directory = tmp_path / "directory.zip"
    with zipfile.ZipFile(huge_directory, "w") as out:
        for i in range(2000):
            out.writestr(f"member_{i:06d}", b"")
    with pytest.raises(PolicyFileError, match=r"directory of [\d,]+ bytes, more than the "
                                              r"65,536 allowed \(64 members\)"):
        load_policy(huge_directory)
    records = io.BytesIO()
    with zipfile.ZipFile(records, "w") as out:
        for i in range(5000):
            out.writestr(f"archive/data/{i}", b"")
    with pytest.raises(PolicyFileError, match=r"policy.pth: .*more than the"):
        load_policy(crafted_zip(tmp_path, "records.zip", weights=records.getvalue()))
    with pytest.raises(PolicyFileError, match=r"policy.pth: not torch's zip format"):
        load_policy(crafted_zip(tmp_path, "legacy.zip", weights=b"\x80\x02}q\x00."))
    path = crafted_zip(tmp_path, "plain.zip")
    monkeypatch.setattr(policy_zip, "MAX_DATA_BYTES", 1000)
    with pytest.raises(PolicyFileError, match=r"member 'data' declares [\d,]+ bytes, more "
                                              r"than the 1,000 allowed"):
        load_policy(path)
    monkeypatch.setattr(policy_zip, "MAX_DATA_BYTES", 2**26)
    monkeypatch.setattr(policy_zip, "MAX_WEIGHTS_BYTES", 1000)
    with pytest.raises(PolicyFileError, match=r"member 'policy.pth' declares [\d,]+ bytes"):
        load_policy(path)


@pytest.mark.parametrize("edit, error, expected", [
    (setter("policy_kwargs", "bogus", value="3"), PolicyFileError,
     r"unknown policy_kwargs \['bogus'\]; allowed: \['net_arch', 'activation_fn'"),
    (setter("policy_kwargs", "features_extractor_kwargs",
            value="{'features_dim': 8, 'nope': 1}"),
     PolicyFileError, r"unknown policy_kwargs features_extractor_kwargs \['nope'\]; allowed: "
                      r"\['features_dim', 'image_keys', 'encoder', 'head', 'temperature'\]"),
    (setter("policy_kwargs", "features_extractor_kwargs", value="[1, 2]"), PolicyFileError,
     r"features_extractor_kwargs must be a mapping"),
    (setter("policy_kwargs", "net_arch", value="'wide'"), PolicyFileError, r"build no network"),
    (setter("policy_kwargs", value=[1, 2]), PolicyFileError,
     r"policy_kwargs must be a JSON object"),
    (setter("observation_space", value=box_space("(4, 4)", "V100000")), PolicyFileError,
     r"observation_space dtype 'V100000' is not one of"),
    (setter("observation_space", value=box_space("(1, 1, 1, 1, 1)")), PolicyFileError,
     r"observation_space shape \(1, 1, 1, 1, 1\) must be 1 to 4 positive"),
    (setter("observation_space", value=box_space("(4, 4)", "float32") | {
        "low_repr": "[0. 0. ... 0.]"}), UntrustedPolicyError,
     r"observation_space low .* lists only some of its values"),
    (setter("observation_space", value=box_space("(4,)", "float32") | {
        "low_repr": "[0. 1. 2.]"}), PolicyFileError,
     r"observation_space low has 3 values; its shape \(4,\) takes 1 or 4"),
    (setter("observation_space", value="Box"), PolicyFileError,
     r"observation_space must be a JSON object"),
    (lambda doc: b"[]", PolicyFileError, r"its data JSON is not an object but list"),
])
def test_malformed_fields_are_one_clear_error_naming_file_and_field(tmp_path, edit, error,
                                                                    expected):
    path = crafted_zip(tmp_path, "edited.zip", edit)
    with pytest.raises(error, match=expected) as caught:
        load_policy(path)
    assert str(caught.value).startswith(path)


def old_module_zip(folder, monkeypatch) -> str:
    """:data:`SOURCE` as homing-gym 0.1 saved zips: its pickled ``policy_kwargs`` name the
    extractor by the package's old module name (``train.extractor``)."""
    with zipfile.ZipFile(SOURCE) as source:
        members = {name: source.read(name) for name in source.namelist()}
    doc = json.loads(members["data"])
    kwargs = pickle.loads(base64.b64decode(doc["policy_kwargs"][":serialized:"]))
    extractor = kwargs["features_extractor_class"]
    old = types.ModuleType("train.extractor")
    setattr(old, extractor.__name__, extractor)
    with monkeypatch.context() as patch:      # pickle names a class by its __module__
        patch.setitem(sys.modules, "train", types.ModuleType("train"))
        patch.setitem(sys.modules, "train.extractor", old)
        patch.setattr(extractor, "__module__", "train.extractor")
        pickled = pickle.dumps(kwargs)
    assert b"train.extractor" in pickled and b"homing_train" not in pickled
    doc["policy_kwargs"].update({
        ":serialized:": base64.b64encode(pickled).decode(),
        "features_extractor_class": f"<class 'train.extractor.{extractor.__name__}'>"})
    members["data"] = json.dumps(doc).encode()
    path = folder / "old_module.zip"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as out:
        for name, payload in members.items():
            out.writestr(name, payload)
    return str(path)


@pytest.mark.parametrize("name", [*sorted(p.stem for p in POLICY_DIR.glob("*.zip")),
                                  "old_module"])
def test_every_shipped_policy_loads_with_and_without_trust_policy(name, tmp_path,
                                                                  monkeypatch):
    """Both loads give the same weights and spaces; ``--trust-policy`` reads a zip of
    homing-gym 0.1 too (``old_module``), whose pickle names the extractor by the
    package's old module name (``train.extractor``)."""
    path = (old_module_zip(tmp_path, monkeypatch) if name == "old_module"
            else POLICY_DIR / f"{name}.zip")
    safe, trusted = load_policy(path), load_policy(path, trust=True)
    assert safe.observation_space == trusted.observation_space
    assert safe.action_space == trusted.action_space
    mine, theirs = safe.policy.state_dict(), trusted.policy.state_dict()
    assert set(mine) == set(theirs)
    assert all(torch.equal(mine[key], theirs[key]) for key in mine)


@pytest.mark.parametrize("text, expected", [
    ("env_kwargs: [1, 2\n", r"config.yml: not readable YAML"),
    ("- 1\n- 2\n", r"config.yml: must map settings to values, got list"),
    ("env_kwargs: [[scene, arena]]\n", r"config.yml: env_kwargs must be a mapping"),
    ("eval_deterministic: 'no'\n", r"config.yml: eval_deterministic must be true or false"),
    ("pretrain_samples: true\n", r"config.yml: pretrain_samples must be an integer >= 0"),
    ("env_id: 5\n", r"config.yml: env_id must be a text"),
    ("x: !!python/object/apply:os.system ['touch {marker}']\n",
     r"config.yml: not readable YAML .*python/object"),
    ("comment: '" + "x" * 2**20 + "'\n", r"config.yml: [\d,]+ bytes, more than the "
                                         r"1,048,576 a settings file may have"),
])
def test_a_bad_run_config_is_one_clear_error_naming_the_file(tmp_path, text, expected):
    marker = tmp_path / "ran"
    (tmp_path / "config.yml").write_text(text.replace("{marker}", str(marker)))
    with pytest.raises(ValueError, match=expected):
        recorded_settings(str(tmp_path / "model.zip"))
    assert not marker.exists()


def test_a_run_config_with_the_fields_read_well_typed_is_taken(tmp_path):
    (tmp_path / "config.yml").write_text(yaml.safe_dump({
        "env_id": "homing_gym/LocalHoming-v0", "env_kwargs": {"scene": "lab"},
        "eval_deterministic": False, "pretrain_samples": 10, "imitation_iterations": 0}))
    settings = recorded_settings(str(tmp_path / "model.zip"))
    assert settings.params == {"deterministic": False}
    assert settings.privileged
