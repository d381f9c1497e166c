"""The INS/SD half from Python: the online filter against `nav-app ins` on the same logs, one
simulated flight, and the error cases."""

import csv
import os
import pathlib
import subprocess

import numpy as np
import pytest

import ita_nav

ROOT = pathlib.Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("flight")
    n = ita_nav.export_run(str(d), filter="kf", seed=7)
    assert n > 0
    return d


def read_csv(path):
    with open(path) as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    return rows[0], rows[1:]


def replay_in_python(d, gate=None):
    f = ita_nav.InsSdFilter(str(d / "landmarks.toml"), str(d / "initial.toml"), gate=gate)
    _, imu = read_csv(d / "imu.csv")
    _, sightings = read_csv(d / "sightings.csv")
    epochs = {}
    for t, lm, frame, x, y, z in sightings:
        epochs.setdefault(float(t), []).append((int(lm), frame, float(x), float(y), float(z)))
    times = sorted(epochs)
    out, k = [], 0
    for row in imu:
        t = float(row[0])
        vals = [float(x) for x in row[1:]]
        f.propagate(t, vals[:3], vals[3:])
        while k < len(times) and times[k] <= t + 1e-6:
            f.update_pointed(t, epochs[times[k]])
            nav = f.navigation()
            out.append([t, nav["lat_rad"], nav["lon_rad"], nav["alt_m"], *nav["vel_ned_mps"]])
            k += 1
    return f, np.array(out)


def test_the_python_filter_equals_nav_app_ins_on_the_same_logs(logs, tmp_path):
    exe = os.environ.get("NAV_APP_BIN")
    if not exe:
        pytest.fail("NAV_APP_BIN is not set (cargo xtask test sets it)")
    sol = tmp_path / "solution.csv"
    subprocess.run(
        [exe, "ins", "--imu", str(logs / "imu.csv"), "--sightings", str(logs / "sightings.csv"),
         "--landmarks", str(logs / "landmarks.toml"), "--init", str(logs / "initial.toml"),
         "--config", str(logs / "scenario.toml"), "--out", str(sol)],
        check=True, capture_output=True, text=True)
    header, rust_rows = read_csv(sol)
    used = header.index("used")
    # Rows at every IMU sample; the epochs' rows carry the update's counts.
    rust = np.array([[float(x) for x in r[:7]] for r in rust_rows if r[used] != ""])
    f, py = replay_in_python(logs)
    assert py.shape == rust.shape and len(py) > 800
    # Same filter code, same parsed numbers: identical to the last bit.
    assert np.array_equal(py, rust)
    s = f.statistics
    assert s["epochs"] == len(py) and s["sightings_rejected"] == 0
    assert f.covariance.shape == (15, 15) and np.all(np.diag(f.covariance) > 0)
    assert f.error_state.shape == (15,)


def test_the_gate_rejects_an_outlier_and_bad_input_raises(logs):
    f = ita_nav.InsSdFilter(str(logs / "landmarks.toml"), str(logs / "initial.toml"), gate=0.9999)
    _, imu = read_csv(logs / "imu.csv")
    _, sightings = read_csv(logs / "sightings.csv")
    first_t = float(sightings[0][0])
    ids = sorted({int(r[1]) for r in sightings})
    for row in imu:
        t = float(row[0])
        vals = [float(x) for x in row[1:]]
        f.propagate(t, vals[:3], vals[3:])
        if t >= first_t - 1e-9:
            break
    good = [(int(lm), fr, float(x), float(y), float(z))
            for tt, lm, fr, x, y, z in sightings if float(tt) == first_t]
    # Landmark 2's direction turned by about 0.3 rad: kilometres off at the landmark.
    lm, fr, x, y, z = good[1]
    bad = good[:1] + [(lm, fr, x + 0.3, y - 0.3, z)] + good[2:]
    r = f.update_pointed(t, bad)
    assert r["rejected"] == 1 and r["used"] == len(good) - 1
    assert f.update(t, [])["used"] == 0  # no sightings: nothing happens
    with pytest.raises(ita_nav.NavError):
        f.propagate(t - 1.0, [0, 0, 0], [0, 0, 0])  # out of order
    with pytest.raises(ita_nav.NavError):
        f.update(t, [(max(ids) + 100, 0.0, 0.0)])  # unknown landmark
    with pytest.raises(ita_nav.NavError):
        f.propagate(t + 0.01, [float("nan"), 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="3 components"):
        f.propagate(t + 0.01, [0, 0], [0, 0, 0])
    with pytest.raises(ita_nav.NavError, match="no-such"):
        ita_nav.InsSdFilter("no-such.toml", str(logs / "initial.toml"))
    with pytest.raises(ValueError, match="filter must be"):
        ita_nav.InsSdFilter(str(logs / "landmarks.toml"), str(logs / "initial.toml"), filter="ekf")
    with pytest.raises(ValueError, match="frame"):
        f.update_pointed(t, [(good[0][0], "enu", 1.0, 0.0, 0.0)])


def test_the_filter_file_the_unaided_mode_and_sightings_from_a_reference(logs, tmp_path):
    # Landmarks and sightings written from the exported truth (radians, with attitude: body
    # directions), then replayed with the mems preset, the paper preset and unaided.
    lm = tmp_path / "landmarks.toml"
    sightings = tmp_path / "sightings.csv"
    sigma = 40.0 ** 0.5  # the paper's sighting noise, what the paper preset assumes
    w = ita_nav.write_sightings(str(logs / "truth.csv"), str(lm), str(sightings), sigma_m=sigma,
                                make_landmarks=12, landmark_range_m=(3000.0, 15000.0),
                                max_range_m=30000.0, seed=3)
    assert w["frame"] == "body" and w["min_per_epoch"] >= 4 and w["sightings"] > 0
    again = tmp_path / "again.csv"
    ita_nav.write_sightings(str(logs / "truth.csv"), str(lm), str(again), sigma_m=sigma,
                            max_range_m=30000.0, seed=3)
    assert sightings.read_bytes() == again.read_bytes()  # seeded
    runs = {}
    for name, kw in {"paper": dict(preset="paper"), "none": dict(preset="paper", filter="none")}.items():
        runs[name] = ita_nav.replay(str(logs / "imu.csv"), str(tmp_path / f"{name}.csv"),
                                    sightings=str(sightings), landmarks=str(lm),
                                    truth=str(logs / "truth.csv"), rate_hz=1.0, **kw)
    aided, free = runs["paper"], runs["none"]
    assert aided["epochs"] > 800 and free["epochs"] == 0
    assert aided["metrics"]["position_m"]["rms"] < free["metrics"]["position_m"]["rms"]
    assert 0.5 < aided["metrics"]["nis_per_dof"] < 2.0
    # A filter file by path that names the preset replays exactly as the preset.
    ff = tmp_path / "filter.toml"
    ff.write_text('preset = "paper"\n')
    by_file = ita_nav.replay(str(logs / "imu.csv"), str(tmp_path / "file.csv"),
                             sightings=str(sightings), landmarks=str(lm),
                             truth=str(logs / "truth.csv"), rate_hz=1.0, filter_file=str(ff))
    assert by_file["metrics"] == aided["metrics"]
    f = ita_nav.InsSdFilter(str(lm), str(logs / "initial.toml"), filter_file=str(ff), filter="none")
    assert f.covariance is not None  # unaided with a filter file: a KF never updated, for its sigma
    with pytest.raises(ita_nav.NavError, match="sigma_m"):
        ff.write_text("[sighting]\nsigma_m = -1.0\n")
        ita_nav.InsSdFilter(str(lm), str(logs / "initial.toml"), filter_file=str(ff))
    with pytest.raises(ita_nav.NavError, match="initial"):
        ita_nav.replay(str(logs / "imu.csv"), str(tmp_path / "x.csv"), filter="none")


def test_a_simulated_flight_is_deterministic_and_the_filter_beats_the_free_ins():
    kf = ita_nav.run_flight(filter="kf", seed=3)
    again = ita_nav.run_flight(filter="kf", seed=3)
    free = ita_nav.run_flight(filter="standalone", seed=3)
    n = len(kf["t_s"])
    assert kf["pos_err_ned_m"].shape == (n, 3) and n > 800
    assert all(np.array_equal(kf[k], again[k], equal_nan=True) for k in kf)
    err_kf = np.linalg.norm(kf["pos_err_ned_m"][-1])
    err_free = np.linalg.norm(free["pos_err_ned_m"][-1])
    assert err_kf < 50.0 < err_free
    assert np.isnan(free["nis"]).all() and np.isfinite(kf["nis"]).any()
    with pytest.raises(ValueError, match="filter must be"):
        ita_nav.run_flight(filter="ekf")


def test_the_monte_carlo_equals_nav_app_monte_carlo(tmp_path):
    exe = os.environ.get("NAV_APP_BIN")
    if not exe:
        pytest.fail("NAV_APP_BIN is not set (cargo xtask python sets it)")
    out = tmp_path / "mc"
    subprocess.run([exe, "monte-carlo", "--config", str(ROOT / "configs" / "paper.toml"),
                    "--runs", "3", "--out", str(out)],
                   check=True, capture_output=True, text=True)
    import json
    rust = json.loads((out / "summary.json").read_text())
    assert rust["schema"] == 1
    py = ita_nav.monte_carlo(runs=3)
    assert py["runs"] == 3 and set(py["modes"]) == {"standalone", "kf", "akf"}
    assert len(py["t_s"]) == len(py["modes"]["kf"]["rms_pos_3d_m"]) and py["t_s"][-1] == 900.0
    for mode in ("standalone", "kf", "akf"):
        m = py["modes"][mode]
        assert m["runs_used"] == 3 and m["excluded"] == []
        at = rust[mode]["at_time_s"]
        for t in ("195", "600", "900"):
            # Same runs (run_seed), same statistics code, same fold order: equal to the bit.
            assert m["rms_pos_3d_m"][int(t)] == at[t]["position_error_rms_m"], (mode, t)
        assert m["final_rms_pos_3d_m"] == at["900"]["position_error_rms_m"]
        assert len(m["final_pos_3d_m"]) == 3
    assert py["modes"]["kf"]["final_rms_pos_3d_m"] < py["modes"]["standalone"]["final_rms_pos_3d_m"]
    assert np.isnan(py["modes"]["standalone"]["mean_nees"]).all()
    with pytest.raises(ValueError, match="filter must be"):
        ita_nav.monte_carlo(runs=1, filters=["kf", "ukf"])
