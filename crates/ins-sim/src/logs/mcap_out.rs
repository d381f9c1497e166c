//! The replay's results as an MCAP file of JSON channels (`nav-app ins --mcap-out`), plottable
//! in Foxglove: `/ins/solution` (the navigation solution with the 1σ of its position, velocity
//! and attitude errors, at the solution rate), `/ins/epochs` (each sighting epoch's NIS, used and
//! rejected), with a reference `/ins/errors` (solution − reference: position, velocity and
//! attitude errors with their σ, at the reference's rows), and `/ins/fix`, the position as
//! `foxglove.LocationFix` with its σ (east-north-up covariance) for the Map panel.
//!
//! Each message is encoded once and the same bytes go to the file and to a [`ReplayTap`] (a
//! live viewer, `nav-app ins --foxglove`), which also paces the replay and can stop it.

use serde::Serialize;

use ins_sd_filter::{InsSdFilter, UpdateReport};
use ros_bag::out::foxglove::{
    COVARIANCE_DIAGONAL_KNOWN, COVARIANCE_UNKNOWN, LOCATION_FIX, LocationFix, Time,
    location_fix_schema,
};
use ros_bag::out::{JsonChannel, JsonMcapWriter};

use super::metrics::ErrorSample;
use crate::SimError;

const SOLUTION_SCHEMA: &str = r#"{"title":"ita_nav.InsSolution","type":"object","properties":{"t_s":{"type":"number"},"lat_deg":{"type":"number"},"lon_deg":{"type":"number"},"alt_m":{"type":"number"},"vel_ned_mps":{"type":"array","items":{"type":"number"},"minItems":3,"maxItems":3},"roll_pitch_yaw_deg":{"type":"array","items":{"type":"number"},"minItems":3,"maxItems":3},"sigma_pos_ned_m":{"type":["array","null"],"items":{"type":"number"}},"sigma_vel_ned_mps":{"type":["array","null"],"items":{"type":"number"}},"sigma_att_mrad":{"type":["array","null"],"items":{"type":"number"}}},"required":["t_s","lat_deg","lon_deg","alt_m","vel_ned_mps","roll_pitch_yaw_deg"]}"#;
const EPOCH_SCHEMA: &str = r#"{"title":"ita_nav.InsEpoch","type":"object","properties":{"t_s":{"type":"number"},"nis":{"type":["number","null"]},"nis_per_dof":{"type":["number","null"]},"used":{"type":"integer"},"rejected":{"type":"integer"}},"required":["t_s","nis","used","rejected"]}"#;
const ERRORS_SCHEMA: &str = r#"{"title":"ita_nav.InsErrors","type":"object","properties":{"t_s":{"type":"number"},"pos_err_ned_m":{"type":"array","items":{"type":["number","null"]}},"vel_err_ned_mps":{"type":"array","items":{"type":["number","null"]}},"att_err_mrad":{"type":"array","items":{"type":["number","null"]}},"sigma_pos_ned_m":{"type":"array","items":{"type":["number","null"]}},"sigma_vel_ned_mps":{"type":"array","items":{"type":["number","null"]}},"sigma_att_mrad":{"type":"array","items":{"type":["number","null"]}}},"required":["t_s","pos_err_ned_m","vel_err_ned_mps","att_err_mrad"]}"#;

#[derive(Serialize)]
struct Solution {
    t_s: f64,
    lat_deg: f64,
    lon_deg: f64,
    alt_m: f64,
    vel_ned_mps: [f64; 3],
    roll_pitch_yaw_deg: [f64; 3],
    sigma_pos_ned_m: Option<[f64; 3]>,
    sigma_vel_ned_mps: Option<[f64; 3]>,
    sigma_att_mrad: Option<[f64; 3]>,
}

#[derive(Serialize)]
struct Epoch {
    t_s: f64,
    nis: Option<f64>,
    nis_per_dof: Option<f64>,
    used: usize,
    rejected: usize,
}

/// JSON writes NaN as null.
fn finite3(v: [f64; 3]) -> [Option<f64>; 3] {
    v.map(|x| x.is_finite().then_some(x))
}

#[derive(Serialize)]
struct Errors {
    t_s: f64,
    pos_err_ned_m: [Option<f64>; 3],
    vel_err_ned_mps: [Option<f64>; 3],
    att_err_mrad: [Option<f64>; 3],
    sigma_pos_ned_m: [Option<f64>; 3],
    sigma_vel_ned_mps: [Option<f64>; 3],
    sigma_att_mrad: [Option<f64>; 3],
}

/// Index of `/ins/solution` in [`ins_channels`].
pub const SOLUTION_CHANNEL: usize = 0;
/// Index of `/ins/epochs` in [`ins_channels`].
pub const EPOCHS_CHANNEL: usize = 1;
/// Index of `/ins/errors` in [`ins_channels`].
pub const ERRORS_CHANNEL: usize = 2;
/// Index of `/ins/fix` in [`ins_channels`].
pub const FIX_CHANNEL: usize = 3;

/// The replay's channels, in the order of the `*_CHANNEL` indices: (topic, schema name, JSON
/// schema).
pub fn ins_channels() -> [(&'static str, &'static str, String); 4] {
    [
        (
            "/ins/solution",
            "ita_nav.InsSolution",
            SOLUTION_SCHEMA.to_owned(),
        ),
        ("/ins/epochs", "ita_nav.InsEpoch", EPOCH_SCHEMA.to_owned()),
        ("/ins/errors", "ita_nav.InsErrors", ERRORS_SCHEMA.to_owned()),
        ("/ins/fix", LOCATION_FIX, location_fix_schema()),
    ]
}

/// Receives a replay's messages as it runs (`nav-app ins --foxglove`), and paces and stops it.
pub trait ReplayTap {
    /// Whether messages of channel `channel` (an index of [`ins_channels`]) are wanted now; when
    /// not and no file is written, the message is not even encoded.
    fn wants(&self, channel: usize) -> bool;
    /// One message of channel `channel` at `t_ns`, JSON (the bytes the file gets).
    fn message(&mut self, channel: usize, t_ns: u64, json: &[u8]);
    /// Called with each IMU sample's time before it is processed (to pace a replay).
    fn pace(&mut self, _t_s: f64) {}
    /// Whether the replay should end now, as if its IMU log ended (Ctrl-C).
    fn stop(&self) -> bool {
        false
    }
}

/// An open `--mcap-out` of a replay.
#[derive(Debug)]
pub struct InsMcapSink {
    writer: JsonMcapWriter,
    channels: [JsonChannel; 4],
}

/// Where the replay's messages go: the file, the tap, both or neither.
pub(super) struct InsSink<'t> {
    file: Option<InsMcapSink>,
    tap: Option<&'t mut dyn ReplayTap>,
    json: Vec<u8>,
}

fn bag(source: ros_bag::BagError) -> SimError {
    SimError::Bag { source }
}

fn t_ns(t_s: f64) -> u64 {
    (t_s.max(0.0) * 1e9).round() as u64
}

impl InsMcapSink {
    /// Creates the file and its channels ([`ins_channels`]).
    ///
    /// # Errors
    /// [`SimError::Bag`].
    pub fn create(path: &std::path::Path) -> Result<Self, SimError> {
        let mut writer = JsonMcapWriter::create(&path.display().to_string()).map_err(bag)?;
        let mut channels = Vec::with_capacity(4);
        for (topic, name, schema) in ins_channels() {
            channels.push(writer.channel(topic, name, &schema).map_err(bag)?);
        }
        let channels = [channels[0], channels[1], channels[2], channels[3]];
        Ok(Self { writer, channels })
    }

    /// Writes the summary and closes the file.
    ///
    /// # Errors
    /// [`SimError::Bag`].
    pub fn finish(self) -> Result<(), SimError> {
        self.writer.finish().map_err(bag)
    }
}

impl<'t> InsSink<'t> {
    pub(super) fn new(file: Option<InsMcapSink>, tap: Option<&'t mut dyn ReplayTap>) -> Self {
        Self {
            file,
            tap,
            json: Vec::new(),
        }
    }

    pub(super) fn tap(&mut self) -> Option<&mut (dyn ReplayTap + 't)> {
        self.tap.as_deref_mut()
    }

    /// Whether the message of `channel` goes anywhere.
    fn wanted(&self, channel: usize) -> bool {
        self.file.is_some() || self.tap.as_ref().is_some_and(|t| t.wants(channel))
    }

    /// Encodes `message` once and hands the bytes to the file and the tap.
    fn emit(&mut self, channel: usize, t_s: f64, message: &impl Serialize) -> Result<(), SimError> {
        let t = t_ns(t_s);
        self.json.clear();
        serde_json::to_writer(&mut self.json, message).map_err(|source| SimError::Encode {
            topic: ins_channels()[channel].0,
            source,
        })?;
        if let Some(f) = self.file.as_mut() {
            f.writer
                .write_json_bytes(f.channels[channel], t, &self.json)
                .map_err(bag)?;
        }
        if let Some(tap) = self.tap.as_deref_mut()
            && tap.wants(channel)
        {
            tap.message(channel, t, &self.json);
        }
        Ok(())
    }

    /// Closes the file.
    pub(super) fn finish(self) -> Result<(), SimError> {
        self.file.map_or(Ok(()), InsMcapSink::finish)
    }

    /// The solution at the filter's time (and the epoch's report, after an update).
    pub(super) fn solution(
        &mut self,
        filter: &InsSdFilter,
        report: Option<&UpdateReport>,
    ) -> Result<(), SimError> {
        let t = filter.time_s();
        if !(self.wanted(SOLUTION_CHANNEL)
            || self.wanted(FIX_CHANNEL)
            || report.is_some() && self.wanted(EPOCHS_CHANNEL))
        {
            return Ok(());
        }
        let s = filter.navigation_solution();
        let (roll, pitch, yaw) = s.att_b_to_n.euler_angles();
        let p = filter.predicted().map(|(_, p)| p);
        let sig = |k: usize, scale: f64| {
            p.as_ref()
                .map(|p| [0, 1, 2].map(|i| p[(k + i, k + i)].max(0.0).sqrt() * scale))
        };
        let msg = Solution {
            t_s: t,
            lat_deg: s.pos.lat_rad.to_degrees(),
            lon_deg: s.pos.lon_rad.to_degrees(),
            alt_m: s.pos.alt_m,
            vel_ned_mps: s.vel_ned_mps.into(),
            roll_pitch_yaw_deg: [roll.to_degrees(), pitch.to_degrees(), yaw.to_degrees()],
            sigma_pos_ned_m: sig(0, 1.0),
            sigma_vel_ned_mps: sig(3, 1.0),
            sigma_att_mrad: sig(6, 1e3),
        };
        if self.wanted(SOLUTION_CHANNEL) {
            self.emit(SOLUTION_CHANNEL, t, &msg)?;
        }
        if self.wanted(FIX_CHANNEL) {
            // NED σ → the east-north-up diagonal.
            let (covariance, kind) = match msg.sigma_pos_ned_m {
                Some([n, e, d]) => (
                    [e * e, 0.0, 0.0, 0.0, n * n, 0.0, 0.0, 0.0, d * d],
                    COVARIANCE_DIAGONAL_KNOWN,
                ),
                None => ([0.0; 9], COVARIANCE_UNKNOWN),
            };
            let fix = LocationFix {
                timestamp: Time::from_ns(t_ns(t)),
                frame_id: "ins",
                latitude: msg.lat_deg,
                longitude: msg.lon_deg,
                altitude: msg.alt_m,
                position_covariance: covariance,
                position_covariance_type: kind,
            };
            self.emit(FIX_CHANNEL, t, &fix)?;
        }
        if let Some(r) = report
            && self.wanted(EPOCHS_CHANNEL)
        {
            let e = Epoch {
                t_s: t,
                nis: r.nis,
                nis_per_dof: r.nis.map(|n| n / (2 * r.used.max(1)) as f64),
                used: r.used,
                rejected: r.rejected,
            };
            self.emit(EPOCHS_CHANNEL, t, &e)?;
        }
        Ok(())
    }

    /// One compared time of the metrics.
    pub(super) fn errors(&mut self, e: &ErrorSample) -> Result<(), SimError> {
        if !self.wanted(ERRORS_CHANNEL) {
            return Ok(());
        }
        let v = |k: usize, scale: f64, a: &[f64; 9]| {
            finite3([a[k] * scale, a[k + 1] * scale, a[k + 2] * scale])
        };
        let msg = Errors {
            t_s: e.t_s,
            pos_err_ned_m: v(0, 1.0, &e.error),
            vel_err_ned_mps: v(3, 1.0, &e.error),
            att_err_mrad: v(6, 1e3, &e.error),
            sigma_pos_ned_m: v(0, 1.0, &e.sigma),
            sigma_vel_ned_mps: v(3, 1.0, &e.sigma),
            sigma_att_mrad: v(6, 1e3, &e.sigma),
        };
        self.emit(ERRORS_CHANNEL, e.t_s, &msg)
    }
}
