"""Landmarks from the panorama (Bekris et al. §4): coloured-blob bearings against the true
bearings of the lab's poster columns, the 0/360 degree seam, and KLT track persistence."""

import math

import numpy as np
import pytest

from homing_baselines.blobs import LAB_COLORS, BlobColor, detect_blobs, largest_blob
from homing_baselines.klt import CornerTracker, KLTConfig, wrap_columns
from homing_gym.geometry import bearing_to, wrap_angle
from homing_gym.scenes.lab import MARKED, POSTER_RADIUS


@pytest.fixture(scope="module")
def lab_env():
    import gymnasium as gym

    env = gym.make("homing_gym/LocalHoming-v0", scene="lab")
    env.reset(seed=0)
    yield env.unwrapped
    env.close()


def test_blob_bearings_match_the_true_bearings_of_the_poster_columns(lab_env):
    landmarks = lab_env.scene.metadata["landmarks"]
    errors = []
    for k, (x, y) in enumerate(MARKED.values()):
        pose = np.array([x, y, 0.7 * k - 2.0])
        blobs = detect_blobs(lab_env.render_panorama(pose))
        assert set(blobs) == set(landmarks)       # every colour seen from every mark
        for name, point in landmarks.items():
            errors.append(abs(wrap_angle(blobs[name].bearing - bearing_to(pose, point))))
    errors = np.degrees(errors)
    assert np.median(errors) < 0.5 and errors.max() < 1.5   # 1.41 deg per column


def test_blob_width_is_the_angle_the_column_spans(lab_env):
    """A column of radius r at distance d spans 2 asin(r / d): within two columns."""
    landmarks = lab_env.scene.metadata["landmarks"]
    for x, y in MARKED.values():
        blobs = detect_blobs(lab_env.render_panorama(np.array([x, y, 0.3])))
        for name, point in landmarks.items():
            truth = 2 * math.asin(POSTER_RADIUS / math.dist((x, y), point))
            assert abs(blobs[name].width - truth) < 2 * 2 * math.pi / 256, name


def test_blob_behind_the_robot_is_one_blob_across_the_seam(lab_env):
    red = lab_env.scene.metadata["landmarks"]["red"]
    x, y = 0.0, 0.5
    away = math.atan2(y - red[1], x - red[0])          # heading away from the red column
    for offset in (-0.01, 0.0, 0.012):                 # straddling the seam both ways
        pose = np.array([x, y, away + offset])
        blob = detect_blobs(lab_env.render_panorama(pose))["red"]
        truth = bearing_to(pose, red)
        assert abs(wrap_angle(blob.bearing - truth)) < math.radians(0.7)
        assert blob.area > 20                           # the whole column, not half of it


def test_largest_blob_joins_the_two_halves_at_the_seam():
    mask = np.zeros((10, 64), np.uint8)
    mask[3:7, 61:] = 255
    mask[3:7, :2] = 255                                  # 5 columns around x = 0 = 64
    mask[1:3, 20:22] = 255                               # a smaller blob elsewhere
    x, y, area, columns = largest_blob(mask)
    assert area == 20 and abs(wrap_columns(x - 63.5, 64)) < 1e-9 and y == 5.0
    assert columns == 5                                  # across the seam
    assert largest_blob(np.full((4, 8), 255, np.uint8)) is None   # no empty column


def test_colours_of_other_objects_are_not_landmarks(lab_env):
    """Only one blob per poster colour, and none of a colour that is not in the room."""
    pose = np.array([0.1, -0.1, 0.0])
    pan = lab_env.render_panorama(pose)
    assert set(detect_blobs(pan, LAB_COLORS + (BlobColor("yellow", 30),))) == \
        {"red", "green", "blue"}


def _texture(seed=0, shape=(48, 256)):
    rng = np.random.default_rng(seed)
    small = rng.integers(0, 256, (shape[0] // 4, shape[1] // 4, 3), dtype=np.uint8)
    return np.kron(small, np.ones((4, 4, 1), np.uint8))


def test_klt_tracks_persist_across_the_seam_with_exact_columns():
    """A panorama rolled by 3 columns per frame (a pure rotation) for a full turn: most
    tracks survive, keep their ids, cross the seam and sit where the roll puts them."""
    image = _texture()
    tracker = CornerTracker(KLTConfig(max_features=60))
    tracker.update(image)
    start = dict(zip(tracker.ids.tolist(), tracker.points[:, 0]))
    for k in range(1, 87):                              # 258 columns: more than a turn
        tracker.update(np.roll(image, 3 * k, axis=1))
        alive = np.isin(tracker.ids, list(start))
        expected = np.array([start[i] for i in tracker.ids[alive]]) + 3 * k
        err = np.abs(wrap_columns(tracker.points[alive, 0] - expected, 256))
        assert err.max() < 0.5
    assert alive.sum() >= 0.8 * len(start)
    assert len(set(tracker.ids.tolist())) == len(tracker.ids)


def test_klt_tracks_persist_while_the_robot_turns_in_the_lab(lab_env):
    tracker = CornerTracker()
    pose = np.array([0.5, 0.3, 0.0])
    tracker.update(lab_env.render_panorama(pose))
    start = dict(zip(tracker.ids.tolist(), tracker.points[:, 0]))
    per_rad = 256 / (2 * math.pi)
    for k in range(1, 43):                              # 0.15 rad a frame: a full turn
        tracker.update(lab_env.render_panorama(pose + np.array([0, 0, 0.15 * k])))
    alive = np.isin(tracker.ids, list(start))
    assert alive.sum() >= 0.5 * len(start) and len(start) >= 40
    expected = np.array([start[i] for i in tracker.ids[alive]]) + 0.15 * 42 * per_rad
    err = np.abs(wrap_columns(tracker.points[alive, 0] - expected, 256))
    assert np.median(err) < 1.5


def test_register_reattaches_features_at_a_predicted_shift():
    image = _texture(1)
    ref = CornerTracker()
    ref.update(image)
    tracker = CornerTracker()
    tracker.update(np.roll(image, 40, axis=1))          # rotated by 40 columns
    n = tracker.register(ref.image, ref.points, ref.ids + 1000, ref.points + [38.0, 0.0])
    assert n >= 0.9 * len(ref.ids)
    got = dict(zip(tracker.ids.tolist(), tracker.points[:, 0]))
    err = [abs(wrap_columns(got[i + 1000] - (x + 40), 256)) for i, x in
           zip(ref.ids.tolist(), ref.points[:, 0]) if i + 1000 in got]
    assert max(err) < 0.5


@pytest.mark.parametrize("make, match", [
    (lambda: BlobColor("red", 200), "hue"),
    (lambda: BlobColor("", 0), "name"),
    (lambda: BlobColor("red", 0, min_saturation=300), "min_saturation"),
    (lambda: KLTConfig(win_size=8), "win_size"),
    (lambda: KLTConfig(max_features=0), "max_features"),
    (lambda: KLTConfig(margin=5), "margin"),
    (lambda: detect_blobs(np.zeros((4, 8), np.uint8)), "uint8"),
    (lambda: detect_blobs(np.zeros((4, 8, 3), np.uint8), (BlobColor("a", 0),) * 2),
     "distinct"),
])
def test_bad_perception_settings_raise(make, match):
    with pytest.raises(ValueError, match=match):
        make()
