"""Self-similar landmarks (Briggs et al. 2000): the pattern, the match function, the
barcode, and the detector on synthetic images."""

import math

import numpy as np
import pytest

import homing_baselines.selfsimilar_detector as det
from homing_baselines.camera_models import PanoramaModel, PerspectiveModel
from homing_baselines.selfsimilar_detector import (DetectorConfig, detect_landmarks,
                                                   match_function, match_points)
from homing_gym.vision import luminance
from homing_gym.selfsimilar import (BARCODE_BANDS, MAX_ID, PanelLayout, barcode_bits,
                                    decode_barcode, panel_image, self_similar)


def _d(p_scale, w, p=2 / 3, n=200_000, seed=0):
    """Monte-Carlo estimate of d_{p_scale, w}(s_p) of Eq. 1-2."""
    x = np.random.default_rng(seed).uniform(0, w, n)
    x = x[x > 0]
    return float(np.mean(np.abs(self_similar(x, p) - self_similar(p_scale * x, p))))


@pytest.mark.parametrize("p", [2 / 3, 0.5, 0.8])
@pytest.mark.parametrize("w", [1.0, 0.3, 7.0])
def test_s_p_is_p_similar_and_sqrt_p_antisimilar(p, w):
    assert _d(p, w, p) < 1e-3                 # d_p = 0 (Eq. 1), up to rounding at edges
    assert _d(math.sqrt(p), w, p) > 0.999     # d_sqrt(p) = 1 (Eq. 2)
    assert 0.1 < _d(p ** 0.25, w, p) < 0.9    # an unrelated scale is neither


def _scanline(origin, sigma, n=400, oversample=10, p=2 / 3, contrast=1.0):
    """A scanline with s_p starting at ``origin`` over ``sigma`` pixels on white,
    synthesised from the continuous function with 10-fold oversampling (Fig. 5)."""
    t = (np.arange(n * oversample) + 0.5) / oversample - origin
    v = np.ones_like(t)
    inside = (t > 0) & (t <= sigma)
    v[inside] = self_similar(t[inside] / sigma, p)
    return 1 - contrast + contrast * v.reshape(n, oversample).mean(axis=1)


@pytest.mark.parametrize("origin,sigma", [(100.0, 50.0), (250.3, 140.0), (37.6, 300.0)])
def test_match_function_peaks_at_the_origin(origin, sigma):
    m = match_function(_scanline(origin, sigma)[None], 2 / 3, 45)[0]
    assert abs(int(np.argmax(m)) - origin) <= 1
    assert 0.5 < m.max() <= 1.0
    # half contrast halves the response (§3: c s_p gives c)
    half = match_function(_scanline(origin, sigma, contrast=0.5)[None], 2 / 3, 45)[0]
    assert half.max() == pytest.approx(m.max() / 2, rel=0.1)


def _eq7(row, x, p, w):
    """Eq. 7 written out directly (float64, np.interp for the in-between pixels)."""
    xi = np.arange(w)
    grid = np.arange(row.size)
    base = row[x + xi]
    anti = np.interp(x + math.sqrt(p) * xi, grid, row)
    similar = np.interp(x + p * xi, grid, row)
    return (np.abs(base - anti).sum() - np.abs(base - similar).sum()) / w


@pytest.mark.parametrize("w,step", [(45, 1), (22, 3), (45, 5)])
def test_compiled_match_function_and_points_agree_with_eq7(w, step):
    rows = np.random.default_rng(2).random((3, 160)).astype(np.float32)
    m = match_function(rows, 2 / 3, w, step)
    xs = np.arange(0, 160 - w + 1, step)
    assert m.shape == (3, xs.size)
    expected = [[_eq7(r.astype(np.float64), x, 2 / 3, w) for x in xs] for r in rows]
    np.testing.assert_allclose(m, expected, atol=2e-6)
    ys, cols = np.meshgrid(np.arange(3), xs, indexing="ij")
    assert np.array_equal(match_points(rows, ys, cols * 1, 2 / 3, w), m)
    # outside the image: -1
    assert match_points(rows, [0, 5, 0], [-1, 0, 160 - w + 1], 2 / 3, w).tolist() == [-1] * 3


def test_compiled_chain_steps_keep_numpys_arithmetic():
    """The compiled per-chain steps give numpy's values bit for bit (so the detector's
    decisions are those of the numpy formulation), and the compiled luminance is BT.601
    to the last bit or two."""
    rng = np.random.default_rng(3)
    for n in (1, 2, 7, 22, 45, 300):
        v = rng.random(n).astype(np.float32)
        for q in (5.0, 95.0):
            assert det._percentile(v, q) == np.percentile(v, [q])[0]
        band = np.add.reduceat(np.append(v, np.float32(0)), [0, n])[0]   # a band's sum
        assert v[0] + np.float32(det._sum(v[1:])) == band
        row = rng.random(n + 2).astype(np.float32)
        x0 = float(rng.uniform(-1, 3))
        expected = np.interp(x0 + np.arange(0, row.size - x0 - 1), np.arange(row.size), row)
        assert np.array_equal(det._profile(row, x0), expected.astype(np.float32))
    ys = np.arange(5, 50, 3.0)
    xs = 0.3 * ys + 7 + rng.normal(0, 0.5, ys.size)
    np.testing.assert_allclose(det._line(ys, xs), np.polyfit(ys, xs, 1), rtol=1e-12)
    image = rng.integers(0, 256, (30, 40, 3), dtype=np.uint8)
    np.testing.assert_allclose(det.to_gray(image), luminance(image), rtol=0, atol=2e-7)


def test_match_function_is_low_on_other_patterns():
    rng = np.random.default_rng(1)
    for line in (np.full(400, 0.4), rng.random(400),
                 np.repeat(rng.random(40), 10)):
        assert match_function(line[None], 2 / 3, 45).max() < 0.2
    # a 3/4-similar wave gives a peak, but a rounded one (Fig. 5d): not a sharp match
    wrong = _scanline(100.3, 140.0, p=0.75)
    found = detect_landmarks(np.tile(wrong, (60, 1)).astype(np.float32),
                             PerspectiveModel.from_fov(400, 60, math.radians(60)),
                             DetectorConfig(require_id=False))
    assert found == []


def test_barcode_round_trip_every_id():
    for i in range(MAX_ID + 1):
        bands = barcode_bits(i)
        assert len(bands) == BARCODE_BANDS and decode_barcode(bands) == i
        for k in range(1, BARCODE_BANDS - 1):   # every single flipped band is caught
            flipped = list(bands)
            flipped[k] ^= 1
            assert decode_barcode(flipped) is None
    with pytest.raises(ValueError, match="landmark id"):
        barcode_bits(MAX_ID + 1)


def _on_background(panel: np.ndarray, shape=(480, 640), at=(150, 120), level=200):
    img = np.full(shape, level, np.uint8)
    y, x = at
    img[y:y + panel.shape[0], x:x + panel.shape[1]] = panel
    return img


def test_detector_reads_every_id_from_a_synthetic_panel():
    layout = PanelLayout()
    model = PerspectiveModel.from_fov(640, 480, math.radians(60))
    for i in range(MAX_ID + 1):
        panel = panel_image(i, layout=layout, pixels_per_metre=400)
        found = detect_landmarks(_on_background(panel), model)
        assert [d.id for d in found] == [i]
        d = found[0]
        assert d.x == pytest.approx(120 + 400 * layout.margin, abs=1.5)
        assert d.height == pytest.approx(400 * layout.pattern_height, abs=3)
        assert d.width == pytest.approx(400 * layout.pattern_width, abs=3)


def test_detector_wraps_around_the_panorama():
    panel = panel_image(9, pixels_per_metre=150)         # pattern 75 pixels wide
    pano = _on_background(panel, shape=(96, 1024), at=(8, 0))
    pano = np.roll(pano, 1024 - 30, axis=1)              # the panel crosses column 0
    model = PanoramaModel(1024, 96)
    found = detect_landmarks(pano, model, DetectorConfig(window=30, row_step=3))
    assert [d.id for d in found] == [9]
    assert found[0].x == pytest.approx(994 + 150 * PanelLayout().margin, abs=1.5)
    centre = 994 + 150 * PanelLayout().width / 2 - 1024
    assert found[0].bearing == pytest.approx(model.bearing(centre), abs=0.01)


def test_speedups_find_the_same_landmark():
    panel = panel_image(3, pixels_per_metre=400)
    img = _on_background(panel)
    model = PerspectiveModel.from_fov(640, 480, math.radians(60))
    plain = detect_landmarks(img, model)
    fast = detect_landmarks(img, model, DetectorConfig(coarse_rows=True, peak_step=5))
    assert [d.id for d in fast] == [d.id for d in plain] == [3]
    assert fast[0].x == pytest.approx(plain[0].x, abs=1.0)


@pytest.mark.parametrize("kwargs,message", [
    ({"p": 1.5}, "p must"), ({"window": 2}, "window"), ({"row_step": 0}, "row_step"),
    ({"min_peak": 0}, "min_peak"), ({"peak_step": 0.5}, "peak_step")])
def test_bad_detector_config_raises(kwargs, message):
    with pytest.raises(ValueError, match=message):
        DetectorConfig(**kwargs)


def test_bad_pattern_arguments_raise():
    with pytest.raises(ValueError, match="p must"):
        self_similar([0.5], p=1.0)
    with pytest.raises(ValueError, match="x > 0"):
        self_similar([0.0])
    with pytest.raises(ValueError, match="contrast"):
        panel_image(0, contrast=0.0)
    with pytest.raises(ValueError, match="pattern_width"):
        PanelLayout(pattern_width=-1)
