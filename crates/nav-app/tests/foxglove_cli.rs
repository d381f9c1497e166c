//! `nav-app --foxglove` end to end with a tungstenite client on loopback: with `--mcap-out` the
//! live messages are the file's, byte for byte and at the same times (with `--camera`, the
//! bird's-eye view's too); without it, the bird's-eye view the encoder thread sends is the
//! `--birdseye` PNG's; `--wait-client` holds the run until the subscription; `--realtime` needs a
//! recorded input.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::collections::BTreeMap;
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use tungstenite::client::IntoClientRequest;
use tungstenite::{Message, WebSocket};

fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// A `foxglove.websocket.v1` client, retried while nav-app starts listening.
fn connect(port: u16) -> WebSocket<TcpStream> {
    let end = Instant::now() + Duration::from_secs(60);
    let stream = loop {
        match TcpStream::connect(("127.0.0.1", port)) {
            Ok(s) => break s,
            Err(e) if Instant::now() > end => panic!("nav-app did not listen on {port}: {e}"),
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    };
    stream
        .set_read_timeout(Some(Duration::from_secs(60)))
        .unwrap();
    let mut request = format!("ws://127.0.0.1:{port}/")
        .into_client_request()
        .unwrap();
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        "foxglove.websocket.v1".parse().unwrap(),
    );
    tungstenite::client(request, stream).unwrap().0
}

type ByTopic = BTreeMap<String, Vec<(u64, Vec<u8>)>>;

/// What a run of nav-app with `args` and `--json --foxglove PORT --wait-client` sent to a
/// client subscribed to every channel (by topic), its stdout lines and its frame count; the run's
/// summary says one client and every message sent, none dropped.
fn serve_and_read(args: &[&str]) -> (ByTopic, Vec<String>, usize) {
    let port = free_port();
    let child = Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .arg("--json")
        .args(args)
        .args(["--foxglove", &format!("127.0.0.1:{port}"), "--wait-client"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut ws = connect(port);
    let mut topics = BTreeMap::new();
    while topics.is_empty() {
        if let Message::Text(t) = ws.read().unwrap() {
            let v: serde_json::Value = serde_json::from_str(t.as_str()).unwrap();
            if v["op"] == "advertise" {
                for c in v["channels"].as_array().unwrap() {
                    topics.insert(
                        c["id"].as_u64().unwrap(),
                        c["topic"].as_str().unwrap().to_owned(),
                    );
                }
            }
        }
    }
    let subscriptions: Vec<_> = topics
        .keys()
        .map(|&id| serde_json::json!({"id": id * 10, "channelId": id}))
        .collect();
    ws.send(Message::text(
        serde_json::json!({"op": "subscribe", "subscriptions": subscriptions}).to_string(),
    ))
    .unwrap();
    let mut live = ByTopic::new();
    loop {
        match ws.read() {
            Ok(Message::Binary(b)) if b[0] == 1 => {
                let sub = u32::from_le_bytes(b[1..5].try_into().unwrap());
                let t_ns = u64::from_le_bytes(b[5..13].try_into().unwrap());
                let topic = topics[&(u64::from(sub) / 10)].clone();
                live.entry(topic)
                    .or_default()
                    .push((t_ns, b[13..].to_vec()));
            }
            Ok(_) => {}
            Err(_) => break,
        }
    }
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<String> = stdout.lines().map(str::to_owned).collect();
    let summary: serde_json::Value = serde_json::from_str(&lines[lines.len() - 1]).unwrap();
    let frames = summary["summary"]["tracked_frames"].as_u64().unwrap() as usize;
    assert!(frames > 10);
    assert_eq!(
        summary["summary"]["foxglove"],
        serde_json::json!({"clients": 1, "sent": topics.len() * frames, "dropped": 0})
    );
    (live, lines, frames)
}

/// The messages of an MCAP file by topic.
fn read_mcap(path: &Path) -> ByTopic {
    let bytes = std::fs::read(path).unwrap();
    let mut file = ByTopic::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        file.entry(m.channel.topic.clone())
            .or_default()
            .push((m.log_time, m.data.into_owned()));
    }
    file
}

/// With `--mcap-out` (and `extra`), every live message is the file's, at the same time, on the
/// `topics`; `/lanes` is the `--json` line.
fn live_equals_file(name: &str, extra: &[&str], topics: &[&str]) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let mcap_path = dir.join("run.mcap");
    let mut args = vec!["--mcap-out", mcap_path.to_str().unwrap()];
    args.extend_from_slice(extra);
    let (live, lines, frames) = serve_and_read(&args);
    let file = read_mcap(&mcap_path);
    assert_eq!(live.keys().collect::<Vec<_>>(), topics);
    assert_eq!(file.keys().collect::<Vec<_>>(), topics);
    for (topic, messages) in &live {
        assert_eq!(messages.len(), frames, "{topic}");
        assert!(messages == &file[topic], "{topic}: live and file differ");
    }
    for ((_, payload), line) in live["/lanes"].iter().zip(&lines) {
        assert_eq!(std::str::from_utf8(payload).unwrap(), line);
    }
}

#[test]
fn live_messages_are_the_mcap_files_byte_for_byte() {
    live_equals_file(
        "foxglove-cli",
        &[],
        &["/camera/image", "/camera/lanes", "/lanes"],
    );
}

#[test]
fn with_a_camera_the_birdseye_view_is_in_the_file_and_live_byte_for_byte() {
    live_equals_file(
        "foxglove-cli-camera",
        &["--camera", "robot"],
        &[
            "/camera/birdseye",
            "/camera/image",
            "/camera/lanes",
            "/lanes",
        ],
    );
}

/// Live only, the encoder thread renders the bird's-eye view: each frame's message is an rgb8
/// `foxglove.RawImage` whose pixels are the `--birdseye` PNG's of the same frame.
#[test]
fn live_only_the_birdseye_view_is_the_png_of_the_same_frame() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("foxglove-cli-birdseye");
    let _ = std::fs::remove_dir_all(&dir);
    let (live, _, frames) =
        serve_and_read(&["--camera", "robot", "--birdseye", dir.to_str().unwrap()]);
    let views = &live["/camera/birdseye"];
    assert_eq!(views.len(), frames);
    for (k, (_, payload)) in views.iter().enumerate() {
        let v: serde_json::Value = serde_json::from_slice(payload).unwrap();
        assert_eq!(
            (&v["encoding"], &v["width"], &v["height"], &v["step"]),
            (
                &serde_json::json!("rgb8"),
                &serde_json::json!(320),
                &serde_json::json!(320),
                &serde_json::json!(960)
            )
        );
        assert_eq!(v["frame_id"], "birdseye");
        let png = image::open(dir.join(format!("birdseye_{k:06}.png")))
            .unwrap()
            .to_rgb8();
        let pixels = base64_decode(v["data"].as_str().unwrap());
        assert!(pixels == png.as_raw().as_slice(), "frame {k} differs");
    }
}

/// Standard base64 (with `=` padding) decoded.
fn base64_decode(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let mut out = Vec::with_capacity(text.len() / 4 * 3);
    for quad in text.as_bytes().chunks(4) {
        let n = quad.iter().take_while(|&&c| c != b'=').count();
        let bits = quad[..n]
            .iter()
            .fold(0u32, |acc, &c| (acc << 6) | u32::from(value(c)))
            << (6 * (4 - n));
        out.extend_from_slice(&bits.to_be_bytes()[1..n]);
    }
    out
}
#[test]
fn realtime_with_a_device_and_wait_client_without_foxglove_are_refused() {
    let out = Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .args(["--wait-client"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--foxglove"));
    let out = Command::new(env!("CARGO_BIN_EXE_nav-app"))
        .args(["--device", "/dev/null", "--realtime", "--json"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--realtime"));
}

/// Every topic `docs/foxglove-layout.json` shows is one nav-app serves (lanes or INS), and every
/// served channel but the annotations' own image is shown or drawn.
#[test]
fn the_layout_file_shows_only_served_topics() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/foxglove-layout.json"),
    )
    .unwrap();
    let layout: serde_json::Value = serde_json::from_str(&text).unwrap();
    let served: Vec<&str> = lane_io::mcap_sink::lane_channels()
        .iter()
        .map(|c| c.0)
        .chain([lane_io::mcap_sink::BIRDSEYE_TOPIC])
        .chain(ins_sim::logs::ins_channels().iter().map(|c| c.0))
        .collect();
    let mut shown = Vec::new();
    collect_topics(&layout["configById"], &mut shown);
    assert!(!shown.is_empty());
    for topic in &shown {
        assert!(served.contains(&topic.as_str()), "{topic} is not served");
    }
    for topic in served {
        assert!(
            shown.iter().any(|s| s == topic),
            "{topic} is not in the layout"
        );
    }
}

/// The topic of `s` (`/a/b` of `/a/b.field[0]`) into `out`, when it names one.
fn add_topic(s: &str, out: &mut Vec<String>) {
    if s.starts_with('/') {
        let topic = s.split('.').next().unwrap().to_owned();
        if !out.contains(&topic) {
            out.push(topic);
        }
    }
}

/// The topics of the strings (and keys) under `v`.
fn collect_topics(v: &serde_json::Value, out: &mut Vec<String>) {
    match v {
        serde_json::Value::String(s) => add_topic(s, out),
        serde_json::Value::Array(a) => a.iter().for_each(|x| collect_topics(x, out)),
        serde_json::Value::Object(o) => {
            for (k, x) in o {
                add_topic(k, out);
                collect_topics(x, out);
            }
        }
        _ => {}
    }
}
