//! Watching a run live: `--foxglove [ADDR]` serves the run's channels over Foxglove's WebSocket
//! protocol (crate `foxglove-live`), `--wait-client` holds the first frame until a client has
//! subscribed, `--realtime` paces a recorded input at its own timestamps; and Ctrl-C (SIGINT),
//! which ends a run cleanly: the loops stop at the next frame or epoch, the files are finished and
//! the summary printed.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use foxglove_live::{ChannelId, LiveConfig, LiveServer, LiveStats};
use lane_io::GreyFrame;
use lane_io::birdseye::BirdseyeView;
use lane_io::encode_thread::EncodeThread;
use lane_io::mcap_sink::{
    ANNOTATIONS, BIRDSEYE, IMAGE, LANES, LaneEncoder, birdseye_channel, lane_channels,
};
use lane_tracker::TrackReport;
use lane_tracker::camera::EgoLaneReport;

/// The address `--foxglove` without a value listens on: loopback only.
pub(crate) const DEFAULT_ADDR: &str = "127.0.0.1:8765";

/// The options shared by the lane tracker and `nav-app ins`.
#[derive(clap::Args, Debug, Clone)]
pub(crate) struct LiveArgs {
    /// Serve the run live to Foxglove (the app's "Open connection" → Foxglove WebSocket →
    /// ws://ADDR) with the same channels as --mcap-out [ADDR default: 127.0.0.1:8765, loopback
    /// only; give e.g. 0.0.0.0:8765 to serve a robot's network].
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = DEFAULT_ADDR)]
    pub foxglove: Option<String>,
    /// With --foxglove: start only once a client has subscribed to a channel.
    #[arg(long, requires = "foxglove")]
    pub wait_client: bool,
    /// Pace a recorded input (file, bag, video, log) at its own timestamps instead of as fast as
    /// possible.
    #[arg(long)]
    pub realtime: bool,
}

/// A live server and its channels (and, for the lanes, the thread that encodes the images, and
/// the bird's-eye view it renders with a camera model).
pub(crate) struct Live {
    server: Arc<LiveServer>,
    channels: Vec<ChannelId>,
    encode: Option<EncodeThread>,
    birdseye: Option<BirdseyeView>,
}

/// One tracked frame's messages for the lane channels.
pub(crate) struct LaneOutput<'a> {
    /// The frame's time, ns.
    pub t_ns: u64,
    pub frame: &'a GreyFrame,
    pub report: &'a TrackReport,
    /// The ego lane, with a camera model.
    pub ego: Option<EgoLaneReport>,
    /// The `/lanes` message: the `--json` line.
    pub lanes_json: &'a [u8],
}

impl Live {
    /// Listens on `addr` and adds `channels` (topic, schema name, JSON schema), in this order.
    pub fn start(addr: &str, channels: &[(&str, &str, String)]) -> Result<Self> {
        let server =
            LiveServer::bind(addr, "nav-app", LiveConfig::default()).context("--foxglove")?;
        let channels = channels
            .iter()
            .map(|(topic, name, schema)| server.add_channel(topic, name, schema))
            .collect::<Result<Vec<_>, _>>()
            .context("--foxglove")?;
        Ok(Self {
            server: Arc::new(server),
            channels,
            encode: None,
            birdseye: None,
        })
    }

    /// Listens on `addr` with the lane channels (`lane_io::mcap_sink::lane_channels`) and, with
    /// a bird's-eye `view` (`--camera`), the bird's-eye channel after them.
    pub fn start_lanes(addr: &str, view: Option<BirdseyeView>) -> Result<Self> {
        let mut channels = lane_channels().to_vec();
        channels.extend(view.as_ref().map(|_| birdseye_channel()));
        let mut live = Self::start(addr, &channels)?;
        live.birdseye = view;
        Ok(live)
    }

    /// The address served (with the port picked when 0 was given).
    pub fn addr(&self) -> std::net::SocketAddr {
        self.server.local_addr()
    }

    /// Whether a client subscribed channel `k` (false for a channel not served).
    pub fn wants(&self, k: usize) -> bool {
        self.channels.get(k).is_some_and(|&c| self.server.wants(c))
    }

    /// [`Self::wants`] for each lane channel (`lane_io::mcap_sink::IMAGE` … `BIRDSEYE`).
    pub fn lane_wants(&self) -> [bool; 4] {
        std::array::from_fn(|k| self.wants(k))
    }

    /// Sends `json` on channel `k` at `t_ns` to the clients that subscribed it.
    pub fn publish(&self, k: usize, t_ns: u64, json: &[u8]) {
        self.server.publish(self.channels[k], t_ns, json);
    }

    /// Moves the clients' clocks to `t_ns`.
    pub fn time(&self, t_ns: u64) {
        self.server.time(t_ns);
    }

    /// `--wait-client`: waits until a client subscribed; false when Ctrl-C came first.
    pub fn wait_client(&self) -> bool {
        eprintln!(
            "nav-app: waiting for a Foxglove client on ws://{} (--wait-client)",
            self.addr()
        );
        while !interrupted() {
            if self.server.wait_subscribed(Duration::from_millis(100)) {
                return true;
            }
        }
        false
    }

    /// One tracked frame of the lane channels at its time, for the channels in `wants`: the
    /// `/lanes` message at once; the image, annotations and bird's-eye view either `encoded`
    /// already (the `--mcap-out` bytes) or by the encoder thread, so that the tracker's thread
    /// only copies the frame.
    pub fn lane_frame(
        &mut self,
        out: &LaneOutput<'_>,
        encoded: Option<&LaneEncoder>,
        wants: [bool; 4],
    ) -> Result<()> {
        let t_ns = out.t_ns;
        self.time(t_ns);
        if wants[LANES] {
            self.publish(LANES, t_ns, out.lanes_json);
        }
        if let Some(encoder) = encoded {
            let messages = [
                (IMAGE, encoder.image_json()),
                (ANNOTATIONS, encoder.annotations_json()),
                (BIRDSEYE, encoder.birdseye_json()),
            ];
            for (k, json) in messages {
                if wants[k] {
                    self.publish(k, t_ns, json);
                }
            }
        } else if wants[IMAGE] || wants[ANNOTATIONS] || wants[BIRDSEYE] {
            let encode = match &mut self.encode {
                Some(e) => e,
                None => {
                    let server = Arc::clone(&self.server);
                    let channels = self.channels.clone();
                    let thread =
                        EncodeThread::start(self.birdseye.clone(), move |k, t_ns, json: &[u8]| {
                            if let Some(&channel) = channels.get(k) {
                                server.publish(channel, t_ns, json);
                            }
                        })?;
                    self.encode.insert(thread)
                }
            };
            encode.offer(t_ns, out.frame, out.report, out.ego, wants);
        }
        Ok(())
    }

    /// Lets the encoder finish, the clients receive what is queued (2 s at most), closes and
    /// returns the counters (messages the encoder was too busy for counted as dropped).
    pub fn shutdown(mut self) -> LiveStats {
        let busy = self.encode.take().map_or(0, EncodeThread::finish);
        let mut stats = match Arc::try_unwrap(self.server) {
            Ok(server) => server.shutdown(),
            Err(shared) => shared.stats(),
        };
        stats.dropped += busy;
        stats
    }
}

/// `--realtime`: sleeps until the wall clock is as far from the first frame as `t_s` is from the
/// first frame's time (in slices, so that Ctrl-C is seen).
#[derive(Debug, Default)]
pub(crate) struct Pacer {
    start: Option<(Instant, f64)>,
}

impl Pacer {
    /// Waits for the time of a frame or epoch stamped `t_s`.
    pub fn wait(&mut self, t_s: f64) {
        let (started, t0_s) = *self.start.get_or_insert((Instant::now(), t_s));
        let due = started + Duration::from_secs_f64((t_s - t0_s).clamp(0.0, 1e9));
        loop {
            let now = Instant::now();
            if now >= due || interrupted() {
                return;
            }
            std::thread::sleep((due - now).min(Duration::from_millis(50)));
        }
    }
}

static INTERRUPTED: AtomicBool = AtomicBool::new(false);

extern "C" fn on_sigint(_: libc::c_int) {
    INTERRUPTED.store(true, Ordering::SeqCst);
}

/// Makes the first Ctrl-C (SIGINT) set a flag that the frame and epoch loops poll instead of
/// killing the process; a second Ctrl-C kills it (`SA_RESETHAND`).
pub(crate) fn install_sigint() {
    // SAFETY: `sigaction` is given a zeroed, then filled, `struct sigaction` that lives across
    // the call; the handler only stores to an atomic, which is async-signal-safe.
    unsafe {
        let mut action: libc::sigaction = std::mem::zeroed();
        action.sa_sigaction = on_sigint as extern "C" fn(libc::c_int) as libc::sighandler_t;
        action.sa_flags = libc::SA_RESETHAND;
        libc::sigemptyset(&mut action.sa_mask);
        libc::sigaction(libc::SIGINT, &action, std::ptr::null_mut());
    }
}

/// Whether Ctrl-C was pressed.
pub(crate) fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// `nav-app ins`'s view of a replay: its messages to the live server, its pace (`--realtime`)
/// and Ctrl-C.
pub(crate) struct InsTap<'a> {
    pub live: Option<&'a Live>,
    pub pacer: Option<Pacer>,
}

impl ins_sim::logs::ReplayTap for InsTap<'_> {
    fn wants(&self, channel: usize) -> bool {
        self.live.is_some_and(|l| l.wants(channel))
    }

    fn message(&mut self, channel: usize, t_ns: u64, json: &[u8]) {
        if let Some(l) = self.live {
            if channel == ins_sim::logs::SOLUTION_CHANNEL {
                l.time(t_ns);
            }
            l.publish(channel, t_ns, json);
        }
    }

    fn pace(&mut self, t_s: f64) {
        if let Some(p) = self.pacer.as_mut() {
            p.wait(t_s);
        }
    }

    fn stop(&self) -> bool {
        interrupted()
    }
}
