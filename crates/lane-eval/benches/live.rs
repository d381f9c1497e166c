//! The tracker thread's cost per frame of `nav-app --json` over the real udacity clip (221
//! frames, 320×240, `lane_bench::data::UDACITY_CLIP`) with and without the live Foxglove server
//! (issue 55: "within 5 % of without, with no client and with one").
//!
//! Each iteration tracks every frame of the clip (decoded into memory once) with a fresh tracker
//! and does per frame what `nav-app`'s frame loop does on its thread: the `--json` object
//! serialized once (`lane_io::lane_frame::LaneFrame`), and with the server the `wants` checks,
//! the *Time* message, `/lanes` published and, for what a client subscribed, the frame handed to
//! the encoder thread (`lane_io::encode_thread`, which encodes and publishes the image and
//! annotations beside the tracker). Criterion's time is per frame
//! (`iter_custom`, the iteration's total over the clip's frames); after each case the mean time
//! of `LaneTracker::track` alone over every frame measured is printed too (what `nav-app` reports
//! as "tracking … µs/frame", the tracker's speed without the output work). Cases:
//! - `no_server`: `nav-app --json`;
//! - `server_no_client`: `nav-app --json --foxglove`, nobody connected;
//! - `server_one_client`: the same with one local tungstenite client subscribed to the three
//!   channels and reading on its own thread (its reading, and the server's client thread, run
//!   beside the tracker on the same machine).
//!
//! Unpaced, the loop hands the encoder and the client frames at thousands a second (about 1 GB/s
//! of images), so on a machine with few cores they take the tracker's core from it. A camera
//! gives 25–30: the `paced_…` cases hand the clip's first [`PACED_FRAMES`] frames at its own rate
//! (25 frames/s) and criterion's time is then `LaneTracker::track`'s own per frame, with no
//! server and with one client reading:
//! - `paced_no_server`, `paced_one_client`.
//!
//! `cargo bench -p lane-eval --bench live -- --warm-up-time 2 --measurement-time 10` (the paced
//! cases take about 1 s an iteration: criterion runs its 20 samples whatever the time asked).
//!
//! Without the clip under the data root (`lane_bench::data`), it says so and measures nothing.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use std::hint::black_box;
use std::net::TcpStream;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

mod common;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use foxglove_live::{ChannelId, LiveConfig, LiveServer};
use lane_io::encode_thread::EncodeThread;
use lane_io::lane_frame::LaneFrame;
use lane_io::mcap_sink::{frame_t_ns, lane_channels};
use lane_tracker::{Estimator, GreyFrame, LaneTracker, Side, TrackerConfig};
use tungstenite::Message;
use tungstenite::client::IntoClientRequest;

/// The server, its three channels (image, annotations, lanes) and the encoder thread.
struct Live {
    server: Arc<LiveServer>,
    channels: [ChannelId; 3],
    encode: EncodeThread,
}

/// The paced cases' frames: one second of the clip at its rate.
const PACED_FRAMES: usize = 25;
/// The clip's frame period (25 frames/s).
const FRAME_PERIOD: Duration = Duration::from_millis(40);

/// One pass over the clip as nav-app's frame loop does it, each frame handed `pace` after the
/// last when paced; returns the time spent, and adds the time spent in `LaneTracker::track` to
/// `track_time`.
fn pass(
    cfg: &TrackerConfig,
    frames: &[GreyFrame],
    mut live: Option<&mut Live>,
    json: &mut Vec<u8>,
    track_time: &mut Duration,
    pace: Option<Duration>,
) -> Duration {
    let (w, h) = (frames[0].width(), frames[0].height());
    let mut tracker = LaneTracker::new(cfg, Estimator::Kif, w, h).unwrap();
    let start = Instant::now();
    for (k, frame) in frames.iter().enumerate() {
        if let Some(period) = pace {
            let due = start + period * u32::try_from(k).unwrap();
            std::thread::sleep(due.saturating_duration_since(Instant::now()));
        }
        let t0 = Instant::now();
        let report = tracker.track(black_box(frame)).unwrap();
        let dt = t0.elapsed();
        *track_time += dt;
        let t_s = k as f64 / 25.0;
        let message = LaneFrame {
            schema: 1,
            frame: k as u64,
            t_s,
            lanes: &report.lanes,
            road: report.road,
            noise: tracker.frame_noise(),
            track_us: dt.as_secs_f64() * 1e6,
            ego_lane: None,
            lane_cov_px: live.is_some().then(|| {
                [Side::Left, Side::Right]
                    .map(|s| tracker.lane_covariance_px(s).map(|p| p.transpose().into()))
            }),
            capture: None,
        };
        json.clear();
        serde_json::to_writer(&mut *json, &message).unwrap();
        black_box(&json);
        if let Some(l) = live.as_deref_mut() {
            let wants = l.channels.map(|c| l.server.wants(c));
            let t_ns = frame_t_ns(t_s);
            l.server.time(t_ns);
            if wants[2] {
                l.server.publish(l.channels[2], t_ns, json);
            }
            if wants[0] || wants[1] {
                l.encode.offer(
                    t_ns,
                    frame,
                    &report,
                    None,
                    [wants[0], wants[1], false, false],
                );
            }
        }
    }
    start.elapsed()
}

/// A client subscribed to the three channels, reading until `stop`.
fn reading_client(server: &LiveServer, stop: Arc<AtomicBool>) -> std::thread::JoinHandle<u64> {
    let addr = server.local_addr();
    let stream = TcpStream::connect(addr).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_millis(100)))
        .unwrap();
    let mut request = format!("ws://{addr}/").into_client_request().unwrap();
    request.headers_mut().insert(
        "Sec-WebSocket-Protocol",
        "foxglove.websocket.v1".parse().unwrap(),
    );
    let mut ws = tungstenite::client(request, stream).unwrap().0;
    ws.send(Message::text(
        r#"{"op":"subscribe","subscriptions":[{"id":1,"channelId":1},{"id":2,"channelId":2},{"id":3,"channelId":3}]}"#,
    ))
    .unwrap();
    std::thread::spawn(move || {
        let mut bytes = 0u64;
        while !stop.load(Ordering::Relaxed) {
            match ws.read() {
                Ok(Message::Binary(b)) => bytes += b.len() as u64,
                Ok(_) => {}
                Err(tungstenite::Error::Io(e))
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                    ) => {}
                Err(_) => break,
            }
        }
        bytes
    })
}

fn live(c: &mut Criterion) {
    let Some(frames) = common::udacity_clip("live") else {
        return;
    };
    let cfg = TrackerConfig::default_preset().unwrap();
    let mut json = Vec::new();
    let mut group = c.benchmark_group("live");
    group.sample_size(20);
    let start_server = || {
        let server = LiveServer::bind("127.0.0.1:0", "bench", LiveConfig::default()).unwrap();
        let channels = lane_channels()
            .map(|(topic, name, schema)| server.add_channel(topic, name, &schema).unwrap());
        let server = Arc::new(server);
        let publisher = Arc::clone(&server);
        let encode = EncodeThread::start(None, move |k, t_ns, json: &[u8]| {
            publisher.publish(channels[k], t_ns, json);
        })
        .unwrap();
        Live {
            server,
            channels,
            encode,
        }
    };
    for case in [
        "no_server",
        "server_no_client",
        "server_one_client",
        "paced_no_server",
        "paced_one_client",
    ] {
        let paced = case.starts_with("paced");
        let clip = if paced {
            &frames[..PACED_FRAMES.min(frames.len())]
        } else {
            &frames[..]
        };
        let n = u32::try_from(clip.len()).unwrap();
        let mut server = (!case.ends_with("no_server")).then(start_server);
        let stop = Arc::new(AtomicBool::new(false));
        let client = case.ends_with("one_client").then(|| {
            let l = server.as_ref().unwrap();
            let handle = reading_client(&l.server, Arc::clone(&stop));
            let end = Instant::now() + Duration::from_secs(10);
            while !l.channels.iter().all(|&ch| l.server.wants(ch)) {
                assert!(Instant::now() < end, "the client did not subscribe");
                std::thread::sleep(Duration::from_millis(1));
            }
            handle
        });
        let (mut track_time, mut tracked) = (Duration::ZERO, 0u64);
        group.bench_function(BenchmarkId::new(case, "udacity_320x240_per_frame"), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let before = track_time;
                    let pace = paced.then_some(FRAME_PERIOD);
                    let spent = pass(
                        &cfg,
                        clip,
                        server.as_mut(),
                        &mut json,
                        &mut track_time,
                        pace,
                    );
                    // Paced, the tracker's own time (the rest is waiting for the next frame).
                    total += if paced { track_time - before } else { spent };
                    tracked += u64::from(n);
                }
                // Criterion divides by `iters`: the time it reports is per frame.
                total / n
            });
        });
        println!(
            "live/{case}: LaneTracker::track alone {:.1} µs per frame (mean over {tracked} frames)",
            track_time.as_secs_f64() * 1e6 / tracked.max(1) as f64
        );
        if let Some(l) = server {
            let busy = l.encode.finish();
            let stats = Arc::try_unwrap(l.server).ok().unwrap().shutdown();
            stop.store(true, Ordering::Relaxed);
            let read = client.map(|h| h.join().unwrap());
            println!(
                "live/{case}: server sent {} messages, dropped {}; {busy} messages left out by the \
                 busy encoder; the client read {:?} bytes",
                stats.sent, stats.dropped, read
            );
        }
    }
    group.finish();
}

criterion_group!(benches, live);
criterion_main!(benches);
