//! The replay's results as an MCAP file of JSON channels (`nav-app ins --mcap-out`), plottable
//! in Foxglove: `/ins/solution` (the navigation solution with the 1σ of its position, velocity
//! and attitude errors, at the solution rate), `/ins/epochs` (each sighting epoch's NIS, used and
//! rejected), and with a reference `/ins/errors` (solution − reference: position, velocity and
//! attitude errors with their σ, at the reference's rows).

use serde::Serialize;

use ins_sd_filter::{InsSdFilter, UpdateReport};
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

/// An open `--mcap-out` of a replay.
#[derive(Debug)]
pub struct InsMcapSink {
    writer: JsonMcapWriter,
    solution: JsonChannel,
    epochs: JsonChannel,
    errors: JsonChannel,
}

fn bag(source: ros_bag::BagError) -> SimError {
    SimError::Bag { source }
}

fn t_ns(t_s: f64) -> u64 {
    (t_s.max(0.0) * 1e9).round() as u64
}

impl InsMcapSink {
    /// Creates the file and its channels.
    ///
    /// # Errors
    /// [`SimError::Bag`].
    pub fn create(path: &std::path::Path) -> Result<Self, SimError> {
        let mut writer = JsonMcapWriter::create(&path.display().to_string()).map_err(bag)?;
        let solution = writer
            .channel("/ins/solution", "ita_nav.InsSolution", SOLUTION_SCHEMA)
            .map_err(bag)?;
        let epochs = writer
            .channel("/ins/epochs", "ita_nav.InsEpoch", EPOCH_SCHEMA)
            .map_err(bag)?;
        let errors = writer
            .channel("/ins/errors", "ita_nav.InsErrors", ERRORS_SCHEMA)
            .map_err(bag)?;
        Ok(Self {
            writer,
            solution,
            epochs,
            errors,
        })
    }

    /// The solution at the filter's time (and the epoch's report, after an update).
    pub(super) fn solution(
        &mut self,
        filter: &InsSdFilter,
        report: Option<&UpdateReport>,
    ) -> Result<(), SimError> {
        let t = filter.time_s();
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
        self.writer
            .write(self.solution, t_ns(t), &msg)
            .map_err(bag)?;
        if let Some(r) = report {
            let e = Epoch {
                t_s: t,
                nis: r.nis,
                nis_per_dof: r.nis.map(|n| n / (2 * r.used.max(1)) as f64),
                used: r.used,
                rejected: r.rejected,
            };
            self.writer.write(self.epochs, t_ns(t), &e).map_err(bag)?;
        }
        Ok(())
    }

    /// One compared time of the metrics.
    pub(super) fn errors(&mut self, e: &ErrorSample) -> Result<(), SimError> {
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
        self.writer
            .write(self.errors, t_ns(e.t_s), &msg)
            .map_err(bag)
    }

    /// Writes the summary and closes the file.
    ///
    /// # Errors
    /// [`SimError::Bag`].
    pub fn finish(self) -> Result<(), SimError> {
        self.writer.finish().map_err(bag)
    }
}
