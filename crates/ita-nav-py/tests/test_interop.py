"""nav-app against independent implementations of its robot and video inputs and outputs: a ROS 2
bag of the real udacity clip written with Python's `mcap` and `mcap-ros2-support` (as
sensor_msgs/msg/Image and as JPEG CompressedImage, plus an IMU topic), an MP4 made with ffmpeg, and
the --mcap-out file read back with Python's mcap reader, its JSON schemas validated with
`jsonschema`. Damaged bags give a clear error, never a crash.
"""

import io
import json
import os
import pty
import select
import subprocess
import tempfile

import jsonschema
import numpy as np
import pytest

from mcap.reader import make_reader
from mcap_ros2.writer import Writer as Ros2Writer

from nav_paths import SAMPLE, exe


IMAGE_MSG = """std_msgs/Header header
uint32 height
uint32 width
string encoding
uint8 is_bigendian
uint32 step
uint8[] data
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec"""

COMPRESSED_MSG = """std_msgs/Header header
string format
uint8[] data
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec"""

IMU_MSG = """std_msgs/Header header
geometry_msgs/Quaternion orientation
float64[9] orientation_covariance
geometry_msgs/Vector3 angular_velocity
float64[9] angular_velocity_covariance
geometry_msgs/Vector3 linear_acceleration
float64[9] linear_acceleration_covariance
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
================================================================================
MSG: geometry_msgs/Quaternion
float64 x
float64 y
float64 z
float64 w
================================================================================
MSG: geometry_msgs/Vector3
float64 x
float64 y
float64 z"""


def read_y4m(path):
    data = path.read_bytes()
    header, rest = data.split(b"\n", 1)
    fields = header.split()
    w = int(next(f[1:] for f in fields if f.startswith(b"W")))
    h = int(next(f[1:] for f in fields if f.startswith(b"H")))
    num, den = next(f[1:] for f in fields if f.startswith(b"F")).split(b":")
    fps = int(num) / int(den)
    frames = []
    while rest.startswith(b"FRAME"):
        _, rest = rest.split(b"\n", 1)
        frames.append(np.frombuffer(rest[: w * h], dtype=np.uint8).reshape(h, w))
        rest = rest[w * h:]
    return frames, fps


def stamp(i, fps):
    t = i / fps
    return {"sec": int(t), "nanosec": int(round((t - int(t)) * 1e9))}


def lanes_of(stdout):
    rows = [json.loads(line) for line in stdout.splitlines()]
    return [(r["t_s"], r["lanes"]) for r in rows if "lanes" in r]


@pytest.fixture(scope="module")
def bags(tmp_path_factory):
    frames, fps = read_y4m(SAMPLE)
    d = tmp_path_factory.mktemp("bags")
    out = {}
    for kind in ("image", "jpeg"):
        path = d / f"udacity_{kind}.mcap"
        with open(path, "wb") as f:
            w = Ros2Writer(f)
            img = w.register_msgdef("sensor_msgs/msg/Image", IMAGE_MSG)
            jpg = w.register_msgdef("sensor_msgs/msg/CompressedImage", COMPRESSED_MSG)
            imu = w.register_msgdef("sensor_msgs/msg/Imu", IMU_MSG)
            for i, fr in enumerate(frames):
                t_ns = int(round(i / fps * 1e9))
                header = {"stamp": stamp(i, fps), "frame_id": "camera"}
                if kind == "image":
                    w.write_message("/camera/image_raw", img, {
                        "header": header, "height": fr.shape[0], "width": fr.shape[1],
                        "encoding": "mono8", "is_bigendian": 0, "step": fr.shape[1],
                        "data": fr.tobytes()}, log_time=t_ns, publish_time=t_ns)
                else:
                    from PIL import Image
                    buf = io.BytesIO()
                    Image.fromarray(fr).save(buf, format="JPEG", quality=95)
                    w.write_message("/camera/image/compressed", jpg, {
                        "header": header, "format": "jpeg", "data": buf.getvalue()},
                        log_time=t_ns, publish_time=t_ns)
                w.write_message("/imu", imu, {
                    "header": header, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
                    "orientation_covariance": [-1.0] + [0.0] * 8,
                    "angular_velocity": {"x": 0.0, "y": 0.0, "z": 0.01},
                    "angular_velocity_covariance": [0.0] * 9,
                    "linear_acceleration": {"x": 0.1, "y": 0.0, "z": 9.81},
                    "linear_acceleration_covariance": [0.0] * 9}, log_time=t_ns, publish_time=t_ns)
            w.finish()
        out[kind] = path
    return out


def test_an_mcap_image_topic_tracks_exactly_like_the_y4m(bags):
    y4m = subprocess.run([exe(), "--input", str(SAMPLE), "--json"], check=True,
                         capture_output=True, text=True)
    bag = subprocess.run([exe(), "--input", str(bags["image"]), "--json"], check=True,
                         capture_output=True, text=True)
    a, b = lanes_of(y4m.stdout), lanes_of(bag.stdout)
    assert len(a) == len(b) == 221
    # Same pixels, same tracker: the same lanes; the time stamps are the messages' (i / fps).
    assert [l for _, l in a] == [l for _, l in b]
    assert all(abs(ta - tb) < 1e-6 for (ta, _), (tb, _) in zip(a, b))


def test_a_jpeg_topic_tracks_both_lanes_and_the_topic_can_be_named(bags):
    r = subprocess.run([exe(), "--input", str(bags["jpeg"]), "--topic", "/camera/image/compressed",
                        "--json"], check=True, capture_output=True, text=True)
    rows = lanes_of(r.stdout)
    assert len(rows) == 221
    both = sum(all(l["coeffs"] is not None for l in lanes) for _, lanes in rows)
    assert both == 221


def test_the_wrong_topic_lists_the_topics(bags):
    r = subprocess.run([exe(), "--input", str(bags["image"]), "--topic", "/imu"],
                       capture_output=True, text=True)
    assert r.returncode == 1
    assert "/imu is sensor_msgs/msg/Imu" in r.stderr and "/camera/image_raw (sensor_msgs/msg/Image)" in r.stderr


def test_mcap_out_reads_back_with_python_and_validates(bags, tmp_path):
    out = tmp_path / "lanes.mcap"
    subprocess.run([exe(), "--input", str(SAMPLE), "--max-frames", "40", "--mcap-out", str(out)],
                   check=True, capture_output=True, text=True)
    counts, schemas = {}, {}
    with open(out, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            assert channel.message_encoding == "json" and schema.encoding == "jsonschema"
            doc = json.loads(message.data)
            s = schemas.setdefault(schema.name, json.loads(schema.data))
            jsonschema.validate(doc, s)
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            if channel.topic == "/camera/lanes":
                # Both lanes as polylines; the road's bottom and horizon, when there are, as
                # lines across the image (two points on one row).
                lanes = [p for p in doc["points"] if len(p["points"]) > 2]
                rows = [p for p in doc["points"] if len(p["points"]) == 2]
                assert len(lanes) == 2 and len(lanes) + len(rows) == len(doc["points"])
                assert all(p["points"][0]["y"] == p["points"][1]["y"] for p in rows)
            if channel.topic == "/camera/image":
                assert doc["width"] == 320 and doc["encoding"] == "mono8"
            if channel.topic == "/lanes":
                # Each held lane's coefficient covariance, also without --camera.
                cov = doc["lane_cov_px"]
                for lane, c in zip(doc["lanes"], cov):
                    if lane["coeffs"] is not None:
                        assert c is not None and all(c[i][i] > 0 for i in range(3)), doc
    assert counts == {"/camera/image": 40, "/camera/lanes": 40, "/lanes": 40}
    assert set(schemas) == {"foxglove.RawImage", "foxglove.ImageAnnotations", "ita_nav.LaneFrame"}


def test_an_mp4_made_with_ffmpeg_tracks_both_lanes_on_every_frame(tmp_path):
    mp4 = tmp_path / "udacity.mp4"
    subprocess.run(["ffmpeg", "-hide_banner", "-v", "error", "-y", "-i", str(SAMPLE), "-c:v", "mpeg4",
                    "-q:v", "2", str(mp4)], check=True)
    r = subprocess.run([exe(), "--input", str(mp4), "--json"], check=True, capture_output=True,
                       text=True)
    rows = lanes_of(r.stdout)
    assert len(rows) == 221
    assert sum(all(l["coeffs"] is not None for l in lanes) for _, lanes in rows) == 221


def test_damaged_bags_are_clear_errors(bags, tmp_path):
    data = bags["image"].read_bytes()
    cases = {
        "truncated": data[: len(data) // 2],
        "bad-crc": data[:5000] + bytes([data[5000] ^ 0xFF]) + data[5001:],
        "not-mcap": b"hello, not an mcap file" * 10,
    }
    for name, blob in cases.items():
        p = tmp_path / f"{name}.mcap"
        p.write_bytes(blob)
        r = subprocess.run([exe(), "--input", str(p), "--json"], capture_output=True, text=True)
        assert r.returncode in (1, 5), (name, r.returncode, r.stderr)
        assert str(p) in r.stderr, (name, r.stderr)
        assert "panicked" not in r.stderr, (name, r.stderr)


def test_nav_app_ins_reads_the_imu_topic_of_a_bag_as_the_same_csv(bags, tmp_path):
    # The bag's /imu: ω = (0, 0, 0.01) rad/s and a = (0.1, 0, 9.81) m/s² in ROS's FLU axes,
    # stamped i / fps. The same samples as an FRD rates CSV (y and z negated) must replay the same.
    frames, fps = read_y4m(SAMPLE)
    csv = tmp_path / "imu.csv"
    rows = ["t_s,gyro_x_radps,gyro_y_radps,gyro_z_radps,accel_x_mps2,accel_y_mps2,accel_z_mps2"]
    for i in range(len(frames)):
        s = stamp(i, fps)
        t = s["sec"] + s["nanosec"] * 1e-9
        rows.append(f"{t!r},0.0,-0.0,-0.01,0.1,-0.0,-9.81")
    csv.write_text("\n".join(rows) + "\n")
    init = tmp_path / "initial.toml"
    init.write_text("t_s = -0.04\nlat_rad = 0.7\nlon_rad = 0.1\nalt_m = 100.0\n"
                    "vel_ned_mps = [0.0, 0.0, 0.0]\natt_quat_wxyz = [1.0, 0.0, 0.0, 0.0]\n")
    outs = {}
    for name, extra in {"bag": ["--imu", str(bags["image"]), "--imu-topic", "/imu"],
                        "csv": ["--imu", str(csv)]}.items():
        out = tmp_path / f"{name}.csv"
        r = subprocess.run([exe(), "ins", *extra, "--filter", "none", "--init", str(init),
                            "--max-gap-s", "1", "--out", str(out)],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        assert "221 IMU samples" in r.stderr, r.stderr
        outs[name] = np.loadtxt(out, delimiter=",", skiprows=1, usecols=range(11))
    assert outs["bag"].shape == outs["csv"].shape
    assert np.allclose(outs["bag"], outs["csv"], rtol=0, atol=1e-9)
    # Without --imu-topic the bag's only IMU topic is taken; a lane bag's image topic is refused.
    r = subprocess.run([exe(), "ins", "--imu", str(bags["image"]), "--imu-topic",
                        "/camera/image_raw", "--filter", "none", "--init", str(init),
                        "--out", str(tmp_path / "x.csv")], capture_output=True, text=True)
    assert r.returncode == 1 and "sensor_msgs/msg/Imu" in r.stderr, r.stderr


def test_nav_app_ins_mcap_out_reads_back_and_validates(tmp_path):
    d = tmp_path / "flight"
    import ita_nav
    ita_nav.export_run(str(d), filter="kf", seed=3)
    out = tmp_path / "ins.mcap"
    r = subprocess.run([exe(), "ins", "--imu", str(d / "imu.csv"), "--sightings", str(d / "sightings.csv"),
                        "--landmarks", str(d / "landmarks.toml"), "--init", str(d / "initial.toml"),
                        "--preset", "paper", "--truth", str(d / "truth.csv"), "--rate", "2",
                        "--out", str(tmp_path / "sol.csv"), "--mcap-out", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    counts = {}
    with open(out, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            doc = json.loads(message.data)
            jsonschema.validate(doc, json.loads(schema.data))
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
    # 900 s: solution rows at 2 Hz (and at the 900 epochs), errors at the 901 truth rows.
    assert counts["/ins/epochs"] == 900
    assert counts["/ins/errors"] == 901
    assert counts["/ins/solution"] >= 1800


def run_with_terminal_stderr(args):
    """Runs nav-app with stderr on a pseudo-terminal and stdout to a file; returns both."""
    try:
        leader, follower = pty.openpty()
    except OSError as e:  # a sandbox without /dev/ptmx
        pytest.skip(f"no pseudo-terminal here: {e}")
    try:
        with tempfile.TemporaryFile() as stdout:
            p = subprocess.Popen(args, stdout=stdout, stderr=follower, stdin=subprocess.DEVNULL)
            os.close(follower)
            err = b""
            while True:
                ready, _, _ = select.select([leader], [], [], 120)
                if not ready:
                    p.kill()
                    pytest.fail("nav-app wrote nothing to its terminal for 120 s")
                try:
                    chunk = os.read(leader, 65536)
                except OSError:  # EIO: the child closed the terminal
                    break
                if not chunk:
                    break
                err += chunk
            assert p.wait(timeout=120) == 0, err.decode(errors="replace")
            stdout.seek(0)
            out = stdout.read()
        return out.decode(errors="replace"), err.decode(errors="replace")
    finally:
        os.close(leader)


def test_a_terminal_gets_a_progress_bar_on_stderr_never_on_stdout_nor_under_json():
    # Long enough (the clip looped to 30 000 frames) for the bar to be drawn.
    base = [exe(), "--input", str(SAMPLE), "--loop", "--max-frames", "30000"]
    out, err = run_with_terminal_stderr(base)
    assert " frames " in err and " lost" in err, err[-2000:]
    assert "\x1b[" in err or "\r" in err, "the bar redraws in place"
    assert " lost" not in out and "\x1b" not in out and "\r" not in out
    # Under --json stdout is the JSON lines only and the terminal gets no bar.
    out, err = run_with_terminal_stderr(base[:-1] + ["2000", "--json"])
    assert len(lanes_of(out)) == 2000
    assert " lost" not in err and "\x1b[" not in err, err[-2000:]
