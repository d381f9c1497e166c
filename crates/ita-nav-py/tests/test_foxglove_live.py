"""nav-app --foxglove against an independent client of Foxglove's WebSocket protocol: Python's
`websockets`, speaking the spec's subprotocol `foxglove.websocket.v1` (foxglove/ws-protocol
docs/spec.md). On the real udacity clip every frame's /lanes message equals the --json line of the
same run, the images are the clip's frames; a second client that never reads changes neither;
a port in use is an error naming it; Ctrl-C leaves a complete --mcap-out and the summary; the memory
stays bounded over 20 000 frames with a stalled client; --realtime paces at the frames' own times.
Loopback only; each test picks a free port.
"""

import base64
import json
import math
import pathlib
import signal
import socket
import struct
import subprocess
import threading
import time

import pytest

import websockets
from websockets.sync.client import connect

from nav_paths import DATA, SAMPLE, data_file, exe

TOPICS = ("/lanes", "/camera/image", "/camera/lanes")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def ws_connect(port):
    """A `foxglove.websocket.v1` client, retried while nav-app starts listening."""
    kwargs = dict(subprotocols=["foxglove.websocket.v1"], max_size=None, open_timeout=10)
    if int(websockets.__version__.split(".")[0]) >= 15:
        kwargs["proxy"] = None
    deadline = time.monotonic() + 60
    while True:
        try:
            return connect(f"ws://127.0.0.1:{port}", **kwargs)
        except (ConnectionRefusedError, OSError):
            if time.monotonic() > deadline:
                raise
            time.sleep(0.05)


def channels_of(ws, topics):
    """Reads serverInfo and advertise messages until every topic of `topics` is known."""
    info = json.loads(ws.recv(timeout=30))
    assert info["op"] == "serverInfo" and "time" in info["capabilities"]
    ids = {}
    while not set(topics) <= set(ids):
        msg = json.loads(ws.recv(timeout=30))
        if msg["op"] == "advertise":
            for c in msg["channels"]:
                assert c["encoding"] == "json" and c["schemaEncoding"] == "jsonschema"
                ids[c["topic"]] = c["id"]
    return ids


def subscribe_op(ids, topics):
    subs = [{"id": 100 + k, "channelId": ids[t]} for k, t in enumerate(topics)]
    return json.dumps({"op": "subscribe", "subscriptions": subs}), {100 + k: t for k, t in enumerate(topics)}


class Reader(threading.Thread):
    """Receives Message Data until the server closes; per topic, a list of (t_ns, payload)."""

    def __init__(self, ws, sub_topics):
        super().__init__(daemon=True)
        self.ws, self.sub_topics = ws, sub_topics
        self.got = {t: [] for t in sub_topics.values()}
        self.times = 0

    def run(self):
        try:
            for msg in self.ws:
                if isinstance(msg, bytes):
                    if msg[0] == 1:
                        sub, t_ns = struct.unpack_from("<IQ", msg, 1)
                        self.got[self.sub_topics[sub]].append((t_ns, msg[13:]))
                    elif msg[0] == 2:
                        self.times += 1
        except websockets.ConnectionClosed:
            pass


def stalled_client(port, topics):
    """A raw socket that upgrades, reads the channel list, subscribes and never reads again."""
    deadline = time.monotonic() + 60
    while True:
        try:
            s = socket.create_connection(("127.0.0.1", port), timeout=30)
            break
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.05)
    s.sendall((f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
               "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
               "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n").encode())
    buf = b""
    while b"\r\n\r\n" not in buf:
        buf += s.recv(4096)
    head, buf = buf.split(b"\r\n\r\n", 1)
    assert b" 101 " in head.split(b"\r\n")[0], head
    buf = bytearray(buf)

    def take(n):
        while len(buf) < n:
            chunk = s.recv(65536)
            assert chunk, "the server closed the connection"
            buf.extend(chunk)
        out = bytes(buf[:n])
        del buf[:n]
        return out

    ids = {}
    while not set(topics) <= set(ids):
        _, n = take(2)
        n &= 0x7F
        if n == 126:
            n = struct.unpack(">H", take(2))[0]
        elif n == 127:
            n = struct.unpack(">Q", take(8))[0]
        msg = json.loads(take(n))
        if msg["op"] == "advertise":
            ids.update({c["topic"]: c["id"] for c in msg["channels"]})
    payload = json.dumps({"op": "subscribe", "subscriptions": [
        {"id": k, "channelId": ids[t]} for k, t in enumerate(topics)]}).encode()
    mask = b"\x01\x02\x03\x04"
    assert len(payload) < 126
    frame = bytes([0x81, 0x80 | len(payload)]) + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload))
    return s, frame


def serve_and_read(args, port, topics, timeout_s, before_subscribe=None, after_subscribe=None):
    """Run nav-app `args` (serving on `port` with --wait-client), connect one reading client,
    call `before_subscribe`, subscribe the reader to `topics`, call `after_subscribe`, wait for
    the run to end and the server to close the connection; nav-app's exit must be 0. Returns its
    stdout, its stderr and the reader."""
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        with ws_connect(port) as ws:
            if before_subscribe is not None:
                before_subscribe()
            op, sub_topics = subscribe_op(channels_of(ws, topics), topics)
            reader = Reader(ws, sub_topics)
            ws.send(op)
            reader.start()
            if after_subscribe is not None:
                after_subscribe()
            out, err = proc.communicate(timeout=timeout_s)
            reader.join(timeout=timeout_s / 5)
            assert not reader.is_alive(), "the server did not close the connection"
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err.decode()
    return out, err, reader


def run_with_clients(port, stalled):
    """nav-app on the clip with --json --foxglove --wait-client, one reading client (and a stalled
    one); the stdout lines, the summary and what the reading client received."""
    args = [exe(), "--input", str(data_file(SAMPLE)), "--json", "--foxglove", f"127.0.0.1:{port}", "--wait-client"]
    raw = []

    def connect_stalled():
        if stalled:
            raw.extend(stalled_client(port, TOPICS))

    def subscribe_stalled():
        if raw:
            raw[0].sendall(raw[1])

    out, err, reader = serve_and_read(args, port, TOPICS, timeout_s=300,
                                      before_subscribe=connect_stalled, after_subscribe=subscribe_stalled)
    lines = out.decode().splitlines()
    summary = json.loads(lines[-1])["summary"]
    if raw:
        raw[0].close()
    return lines[:-1], summary, reader


def without_time(line):
    d = json.loads(line)
    d.pop("track_us")
    return d


def test_every_frames_lanes_reach_a_websocket_v1_client_equal_to_the_json_lines():
    first = run_with_clients(free_port(), stalled=False)
    second = run_with_clients(free_port(), stalled=True)
    for lines, summary, reader in (first, second):
        assert summary["exit"] == "end" and summary["tracked_frames"] == len(lines) > 200
        lanes = reader.got["/lanes"]
        # The same bytes as the --json line, frame by frame, stamped with the frame's own time.
        assert [p.decode() for _, p in lanes] == lines
        assert [t for t, _ in lanes] == [round(max(json.loads(l)["t_s"], 0) * 1e9) for l in lines]
        # The images and annotations are encoded off the tracker's thread: when the encoder is
        # behind (a file tracked as fast as it goes) a frame's are dropped and counted, never the
        # lanes. Every message is accounted for.
        images, annotations = reader.got["/camera/image"], reader.got["/camera/lanes"]
        assert len(images) > 0 and len(images) == len(annotations)
        stamps = [t for t, _ in lanes]
        assert [t for t, _ in images] == [t for t in stamps if t in {t for t, _ in images}]
        img = json.loads(images[0][1])
        assert (img["width"], img["height"], img["encoding"]) == (320, 240, "mono8")
        assert len(base64.b64decode(img["data"])) == 320 * 240
        assert reader.times == len(lines)
        fox = summary["foxglove"]
        assert set(fox) == {"clients", "sent", "dropped"}
    # The stalled client changes neither the first client's lanes nor the frame count.
    assert [without_time(l) for l in first[0]] == [without_time(l) for l in second[0]]
    fox = first[1]["foxglove"]
    received = sum(len(v) for v in first[2].got.values())
    assert fox["clients"] == 1 and fox["sent"] == received
    assert fox["sent"] + fox["dropped"] == 3 * len(first[0])
    assert second[1]["foxglove"]["clients"] == 2


def test_a_port_in_use_is_an_error_naming_it():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        r = subprocess.run([exe(), "--json", "--foxglove", f"127.0.0.1:{port}"],
                           capture_output=True, text=True, timeout=120)
    assert r.returncode == 1
    assert f"127.0.0.1:{port}: address already in use" in r.stderr
    summary = json.loads(r.stdout.splitlines()[-1])["summary"]
    assert summary["exit"] == "error" and "address already in use" in summary["error"]


def test_ctrl_c_ends_the_run_with_the_summary_and_a_complete_mcap(tmp_path):
    mcap_reader = pytest.importorskip("mcap.reader")
    out = tmp_path / "run.mcap"
    args = [exe(), "--input", str(data_file(SAMPLE)), "--loop", "--max-frames", "10000000", "--json",
            "--mcap-out", str(out), "--foxglove", f"127.0.0.1:{free_port()}"]
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines = [proc.stdout.readline() for _ in range(300)]
    proc.send_signal(signal.SIGINT)
    rest, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    summary = json.loads(rest.splitlines()[-1])["summary"]
    assert summary["exit"] == "interrupted" and summary["tracked_frames"] >= len(lines)
    with open(out, "rb") as f:
        reader = mcap_reader.make_reader(f)
        stats = reader.get_summary().statistics
        assert stats.message_count == 3 * summary["tracked_frames"]


def vm_kb(pid, field):
    for line in pathlib.Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1])
    raise AssertionError(f"no {field} in /proc/{pid}/status")


def test_memory_stays_bounded_over_20000_frames_with_a_stalled_client():
    port = free_port()
    args = [exe(), "--input", str(data_file(SAMPLE)), "--loop", "--max-frames", "20000", "--json",
            "--foxglove", f"127.0.0.1:{port}", "--wait-client"]
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        raw, frame = stalled_client(port, TOPICS)
        raw.sendall(frame)
        peaks = {}
        for k in range(1, 20001):
            proc.stdout.readline()
            if k in (2000, 19000):
                peaks[k] = vm_kb(proc.pid, "VmHWM")
        rest, err = proc.communicate(timeout=600)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    summary = json.loads(rest.splitlines()[-1])["summary"]
    assert summary["tracked_frames"] == 20000
    assert summary["foxglove"]["dropped"] > 0
    # The stalled client's queue is capped (64 MiB of payload, 4 MiB of write buffer), and it
    # fills within the first thousand frames: the peak resident size does not grow after that.
    growth_mb = (peaks[19000] - peaks[2000]) / 1024
    assert growth_mb < 16, f"peak RSS grew {growth_mb:.1f} MB between frames 2000 and 19000"
    raw.close()


def test_realtime_paces_the_frames_at_their_own_times():
    frames = 50
    start = time.monotonic()
    r = subprocess.run([exe(), "--input", str(data_file(SAMPLE)), "--json", "--realtime",
                        "--max-frames", str(frames)], capture_output=True, text=True, timeout=120)
    wall_s = time.monotonic() - start
    assert r.returncode == 0, r.stderr
    t = [json.loads(l)["t_s"] for l in r.stdout.splitlines()[:-1]]
    assert len(t) == frames and wall_s >= t[-1] - t[0]


def test_ins_solution_rows_reach_the_client_equal_to_the_csv(tmp_path):
    d = DATA / "ins" / "rtkexp_drive0708"
    imu, truth = data_file(d / "imu.csv"), data_file(d / "truth.csv")
    lm, s, sol = tmp_path / "lm.toml", tmp_path / "s.csv", tmp_path / "sol.csv"
    subprocess.run([exe(), "ins", "sightings", "--reference", str(truth), "--landmarks", str(lm),
                    "--make-landmarks", "60", "--landmark-range-m", "30", "200", "--max-range-m", "500",
                    "--seed", "7", "--out", str(s)], check=True, capture_output=True)
    port = free_port()
    args = [exe(), "ins", "--imu", str(imu), "--truth", str(truth), "--sightings", str(s),
            "--landmarks", str(lm), "--filter", "kf", "--align-s", "30", "--out", str(sol),
            "--foxglove", f"127.0.0.1:{port}", "--wait-client"]
    topics = ("/ins/solution", "/ins/fix", "/ins/epochs", "/ins/errors")
    _, err, reader = serve_and_read(args, port, topics, timeout_s=600)
    assert b"0 dropped" in err, err.decode()
    header, *rows = sol.read_text().splitlines()
    cols = header.split(",")
    csv = [dict(zip(cols, r.split(","))) for r in rows]
    got = [json.loads(p) for _, p in reader.got["/ins/solution"]]
    assert len(got) == len(csv) > 1000
    for g, c in zip(got, csv):
        assert g["t_s"] == float(c["t_s"])
        assert g["alt_m"] == float(c["alt_m"])
        assert g["vel_ned_mps"] == [float(c[k]) for k in ("vel_n_mps", "vel_e_mps", "vel_d_mps")]
        assert abs(math.radians(g["lat_deg"]) - float(c["lat_rad"])) < 1e-15
        assert abs(math.radians(g["lon_deg"]) - float(c["lon_rad"])) < 1e-15
        if c["sigma_n_m"]:
            assert g["sigma_pos_ned_m"] == [float(c[k]) for k in ("sigma_n_m", "sigma_e_m", "sigma_d_m")]
            assert g["sigma_vel_ned_mps"] == [float(c[k]) for k in ("sigma_vn_mps", "sigma_ve_mps", "sigma_vd_mps")]
    fixes = [json.loads(p) for _, p in reader.got["/ins/fix"]]
    assert len(fixes) == len(got)
    assert all(f["latitude"] == g["lat_deg"] and f["longitude"] == g["lon_deg"] for f, g in zip(fixes, got))
    assert fixes[-1]["position_covariance_type"] == 2
    epochs = sum(1 for c in csv if c["used"])
    assert len(reader.got["/ins/epochs"]) == epochs > 100
    assert len(reader.got["/ins/errors"]) > 100
