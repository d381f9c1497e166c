"""The Python package against the Rust binary, on the real udacity clip (from the data root) and a rendered curve; and its error cases.

Run by `cargo xtask test` (step `python`), which builds the wheel into target/py-venv and sets
NAV_APP_BIN to the nav-app binary of the same checkout. By hand:
    NAV_APP_BIN=target/debug/nav-app target/py-venv/bin/python -m pytest crates/ita-nav-py/tests
"""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import ita_nav

ROOT = pathlib.Path(__file__).resolve().parents[3]
# Third-party data is never in the repository: the real udacity clip is read from the data root.
DATA = pathlib.Path(os.environ.get("ITA_NAV_DATA", ROOT.parent / "shared" / "data"))
SAMPLE = DATA / "udacity" / "solidWhiteRight-320x240-gray.y4m"
if not SAMPLE.exists():
    raise FileNotFoundError(
        f"{SAMPLE}: missing the real udacity clip (third-party evaluation data, not in the "
        "repository): put the shared data root beside the checkout as ../shared/data, or name it "
        "with ITA_NAV_DATA"
    )
# Rendered by `cargo xtask python` (`cargo xtask fixtures`) before pytest runs: the frames are not
# committed, only their ground truth.
SYNTHETIC = pathlib.Path(
    os.environ.get("ITA_NAV_SYNTHETIC", ROOT / "target" / "fixtures" / "synthetic")
) / "curve_left_dashed.y4m"


def rust_run(clip, *extra):
    """nav-app --json on `clip`: the per-frame lane dicts, in frame order."""
    exe = os.environ.get("NAV_APP_BIN")
    if not exe:
        pytest.fail("NAV_APP_BIN is not set (cargo xtask test sets it to the nav-app binary)")
    out = subprocess.run(
        [exe, "--input", str(clip), "--json", *extra], check=True, capture_output=True, text=True
    ).stdout
    frames = [json.loads(line) for line in out.splitlines()]
    return [f for f in frames if "lanes" in f]


@pytest.mark.parametrize("clip", [SAMPLE, SYNTHETIC], ids=["udacity-221", "synthetic-curve"])
@pytest.mark.parametrize("estimator", ["kif", "wrls"])
def test_python_lanes_equal_the_rust_binary_frame_by_frame(clip, estimator):
    frames = ita_nav.read_frames(str(clip))
    rust = rust_run(clip, "--estimator", estimator)
    assert len(frames) == len(rust) > 0
    tracker = ita_nav.LaneTracker(estimator=estimator)
    for i, (frame, r) in enumerate(zip(frames, rust)):
        lanes = tracker.track(frame)
        for py_lane, rust_lane in zip(lanes, r["lanes"]):
            assert py_lane["side"] == rust_lane["side"], i
            assert py_lane["state"] == rust_lane["state"], i
            assert py_lane["points"] == rust_lane["points"], i
            rc = rust_lane["coeffs"]
            # Same code, same pixels: the coefficients are bit-identical (JSON floats round-trip).
            assert (py_lane["coeffs"] is None) == (rc is None), i
            if rc is not None:
                assert list(py_lane["coeffs"]) == rc, (i, py_lane["coeffs"], rc)


def test_the_real_udacity_frames_have_both_lanes_on_every_frame():
    tracker = ita_nav.LaneTracker()
    frames = ita_nav.read_frames(str(SAMPLE))
    assert len(frames) == 221
    for frame in frames:
        left, right = tracker.track(frame)
        assert left["coeffs"] is not None and right["coeffs"] is not None
        assert left["side"] == "left" and right["side"] == "right"
    assert tracker.frame_shape == (240, 320)
    assert tracker.counters["frames"] == 221


def plain(lanes):
    """Lanes with the covariance arrays as nested lists (comparable with ==)."""
    return [{k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in l.items()} for l in lanes]


def test_an_rgb_frame_is_converted_with_bt601_luma():
    frame = ita_nav.read_frames(str(SAMPLE))[0]
    grey_lanes = ita_nav.LaneTracker().track(frame)
    # R = G = B = Y: BT.601 luma gives Y back, so the lanes are the grey frame's.
    rgb = np.repeat(frame[:, :, None], 3, axis=2)
    assert plain(ita_nav.LaneTracker().track(rgb)) == plain(grey_lanes)
    # A pure red frame is 0.299·255 ≈ 76 grey: no lanes, but no error.
    red = np.zeros((240, 320, 3), np.uint8)
    red[:, :, 0] = 255
    left, right = ita_nav.LaneTracker().track(red)
    assert left["coeffs"] is None and right["coeffs"] is None


def test_reset_forgets_the_lanes_so_the_next_frame_initialises():
    frames = ita_nav.read_frames(str(SAMPLE))
    t = ita_nav.LaneTracker()
    for f in frames[:5]:
        t.track(f)
    assert not any(lane["initialised"] for lane in t.track(frames[5]))
    t.reset()
    assert all(lane["initialised"] for lane in t.track(frames[6]))


def test_frames_are_read_in_place_when_contiguous_and_refused_when_not():
    frame = ita_nav.read_frames(str(SAMPLE))[0]
    t = ita_nav.LaneTracker()
    t.track(frame)
    with pytest.raises(ValueError, match="not C-contiguous"):
        t.track(np.asfortranarray(frame))
    wide = np.zeros((240, 640), np.uint8)
    with pytest.raises(ValueError, match="not C-contiguous"):
        ita_nav.LaneTracker().track(wide[:, ::2])


@pytest.mark.parametrize(
    "bad, pattern",
    [
        (np.zeros((240, 320), np.float64), "dtype float64"),
        (np.zeros((240, 320), np.uint16), "dtype uint16"),
        (np.zeros(320, np.uint8), r"shape \(320,\)"),
        (np.zeros((240, 320, 4), np.uint8), "C = 3"),
        ([[0, 1], [2, 3]], "numpy uint8 array"),
    ],
)
def test_a_wrong_dtype_or_shape_is_a_type_error_naming_it(bad, pattern):
    with pytest.raises(TypeError, match=pattern):
        ita_nav.LaneTracker().track(bad)


def test_a_frame_of_another_size_is_refused():
    t = ita_nav.LaneTracker()
    t.track(np.zeros((240, 320), np.uint8))
    with pytest.raises(ValueError, match="240×320"):
        t.track(np.zeros((120, 160), np.uint8))
    with pytest.raises(ita_nav.NavError, match="zero-size|2×2|tracker"):
        ita_nav.LaneTracker().track(np.zeros((2, 2), np.uint8))


def test_bad_configuration_and_estimator_are_named(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(ita_nav.DEFAULT_CONFIG_TOML.replace("r_sigma_px = 2.0", "r_sigma_px = -1.0"))
    with pytest.raises(ita_nav.NavError, match="filter.r_sigma_px"):
        ita_nav.LaneTracker(config=str(bad))
    with pytest.raises(ita_nav.NavError, match="no-such-file.toml"):
        ita_nav.LaneTracker(config=str(tmp_path / "no-such-file.toml"))
    with pytest.raises(ValueError, match="kif"):
        ita_nav.LaneTracker(estimator="ekf")
    with pytest.raises(ita_nav.NavError):
        ita_nav.read_frames(str(tmp_path / "missing.y4m"))


def test_presets_load_by_name():
    for name in ("default", "outdoor", "indoor"):
        assert repr(ita_nav.LaneTracker(config=name)).startswith("LaneTracker(")


def test_covariance_and_metric_ego_lane_equal_the_rust_binary():
    frames = ita_nav.read_frames(str(SAMPLE))
    rust = rust_run(SAMPLE, "--camera", "highway")
    tracker = ita_nav.LaneTracker(camera="highway")
    held = 0
    for i, (frame, r) in enumerate(zip(frames, rust)):
        lanes = tracker.track(frame)
        for k, lane in enumerate(lanes):
            cov_rust = r["lane_cov_px"][k]
            assert (lane["covariance"] is None) == (cov_rust is None), i
            if cov_rust is not None:
                assert lane["covariance"].shape == (3, 3)
                assert lane["covariance"].tolist() == cov_rust, i
        ego = tracker.ego_lane
        assert (ego is None) == (r["ego_lane"] is None), i
        if ego is not None:
            held += 1
            assert ego == r["ego_lane"], i
            assert ego["lane_width_m_sigma"] > 0
    assert held == len(frames)
    tracker.reset()
    assert tracker.ego_lane is None


def test_without_a_camera_there_is_no_ego_lane_and_a_wrong_camera_is_refused():
    frame = ita_nav.read_frames(str(SAMPLE))[0]
    t = ita_nav.LaneTracker()
    t.track(frame)
    assert t.ego_lane is None
    with pytest.raises(ita_nav.NavError, match="image_size_px"):
        ita_nav.LaneTracker(camera="highway").track(np.zeros((180, 320), np.uint8))
    with pytest.raises(ita_nav.NavError):
        ita_nav.LaneTracker(camera="no-such-camera.toml")
