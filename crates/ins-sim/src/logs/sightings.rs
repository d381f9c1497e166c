//! Sightings written from a reference trajectory and a landmark table, so that a filter can be
//! tried on any real IMU log with a reference: [`write_sightings`]; and a landmark table placed
//! around a reference, seeded: [`landmarks_around`].
//!
//! At every epoch t = t₀ + k·period inside the reference (not across a reference gap longer than
//! `max_reference_gap_s`), the reference pose is interpolated at t and every landmark within
//! `[min_range_m, max_range_m]` and inside the field of regard (a cone of half-angle
//! `field_of_regard_deg` about the body's forward axis; about the direction of motion for a
//! reference without attitude) is a candidate; the `max_per_epoch` nearest are sighted. Each
//! sighting is the true line of sight displaced by independent N(0, σ²) offsets in metres at the
//! landmark along the true camera's image axes (`sighting_model::los_from_truth`), written as a
//! unit vector in body axes when the reference has an attitude, else in local-level axes, or in
//! the frame the plan asks for ([`SightingPlan::frame`], [`sighting_model::LosFrame`]; a body
//! direction needs the true attitude). Everything is drawn
//! from one ChaCha8 stream seeded with `seed`: the same inputs give the same file.

use std::io::Write;
use std::path::Path;

use ins_errors::earth::Geodetic;
/// The frame of a sighting's direction ([`SightingPlan::frame`]).
pub use ins_sd_filter::LosFrame;
use ins_sd_filter::{LandmarkEntry, LandmarkTable, nav_pose};
use nalgebra::{UnitQuaternion, Vector2, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

use super::POINTED_SIGHTINGS_HEADER;
use super::csv::io_err;
use super::reference::{ReferenceRow, attitude_from_motion, interpolate};
use crate::SimError;

/// How sightings are drawn from a reference ([`write_sightings`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SightingPlan {
    /// σ of the offsets w and h, m at the landmark.
    pub sigma_m: f64,
    /// Time between epochs, s.
    pub period_s: f64,
    /// Nearest slant range sighted, m.
    pub min_range_m: f64,
    /// Farthest slant range sighted, m.
    pub max_range_m: f64,
    /// Half-angle of the field of regard about the body's forward axis, ° (180: all around).
    pub field_of_regard_deg: f64,
    /// At most this many (the nearest) landmarks per epoch.
    pub max_per_epoch: usize,
    /// No epoch across a reference gap longer than this, s.
    pub max_reference_gap_s: f64,
    /// Seed of the noise.
    pub seed: u64,
    /// The frame of the directions written: `None` (the default) body axes when every reference
    /// row has an attitude, else local-level (NED) axes; `Some(LosFrame::Body)` needs the
    /// attitude in every row; `Some(LosFrame::LocalLevel)` writes NED directions whatever the
    /// reference holds (the same draws: a NED direction is the body one rotated by the
    /// reference attitude).
    pub frame: Option<LosFrame>,
}

impl Default for SightingPlan {
    fn default() -> Self {
        Self {
            sigma_m: 1.0,
            period_s: 1.0,
            min_range_m: 1.0,
            max_range_m: 1000.0,
            field_of_regard_deg: 180.0,
            max_per_epoch: 6,
            max_reference_gap_s: 1.5,
            seed: 1,
            frame: None,
        }
    }
}

/// What [`write_sightings`] wrote.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SightingsWritten {
    /// Epochs with at least one sighting.
    pub epochs: usize,
    /// Sightings written.
    pub sightings: usize,
    /// Fewest landmarks at an epoch (over the epochs inside the reference).
    pub min_per_epoch: usize,
    /// Epochs inside the reference with no landmark in view.
    pub empty_epochs: usize,
    /// The frame the directions are in.
    pub frame_is_body: bool,
}

fn check_plan(plan: &SightingPlan) -> Result<(), SimError> {
    let positive = [
        ("sigma_m", plan.sigma_m),
        ("period_s", plan.period_s),
        ("max_range_m", plan.max_range_m),
        ("max_reference_gap_s", plan.max_reference_gap_s),
    ];
    for (field, v) in positive {
        if !(v.is_finite() && v > 0.0) {
            return Err(SimError::invalid(field, "must be finite and > 0", v));
        }
    }
    if !(plan.min_range_m.is_finite()
        && plan.min_range_m >= 0.0
        && plan.min_range_m < plan.max_range_m)
    {
        return Err(SimError::invalid(
            "min_range_m",
            "must be >= 0 and below max_range_m",
            plan.min_range_m,
        ));
    }
    if !(plan.field_of_regard_deg > 0.0 && plan.field_of_regard_deg <= 180.0) {
        return Err(SimError::invalid(
            "field_of_regard_deg",
            "must be within (0, 180]",
            plan.field_of_regard_deg,
        ));
    }
    if plan.max_per_epoch == 0 {
        return Err(SimError::invalid(
            "max_per_epoch",
            "must be >= 1",
            plan.max_per_epoch,
        ));
    }
    Ok(())
}

/// Writes a pointed-sightings log (`POINTED_SIGHTINGS_HEADER`) from `reference` and `table`
/// (module documentation) to `out` (`out_path` names it in errors).
///
/// # Errors
/// [`SimError::ScenarioInvalid`] for a bad plan, [`SimError::ReferenceSpan`] for an empty
/// reference, [`SimError::LogIo`] when writing fails.
pub fn write_sightings(
    reference: &[ReferenceRow],
    table: &LandmarkTable,
    plan: &SightingPlan,
    out: &mut impl Write,
    out_path: &Path,
) -> Result<SightingsWritten, SimError> {
    check_plan(plan)?;
    let (Some(first), Some(last)) = (reference.first(), reference.last()) else {
        return Err(SimError::ReferenceSpan {
            t_s: 0.0,
            what: "the reference trajectory is empty",
        });
    };
    let attitude_in_every_row = reference.iter().all(|r| r.att_b_to_n.is_some());
    let frame = match plan.frame {
        Some(LosFrame::Body) if !attitude_in_every_row => {
            return Err(SimError::invalid(
                "frame",
                "body directions need the reference's attitude in every row (this reference \
                 has rows without one): write local-level directions (ned)",
                "body",
            ));
        }
        Some(frame) => frame,
        None if attitude_in_every_row => LosFrame::Body,
        None => LosFrame::LocalLevel,
    };
    let wio = io_err(out_path);
    writeln!(out, "{POINTED_SIGHTINGS_HEADER}").map_err(&wio)?;
    let mut rng = ChaCha8Rng::seed_from_u64(plan.seed);
    let cos_for = plan.field_of_regard_deg.to_radians().cos();
    let mut written = SightingsWritten {
        min_per_epoch: usize::MAX,
        frame_is_body: frame == LosFrame::Body,
        ..Default::default()
    };
    let mut cursor = 0;
    let mut in_view: Vec<(f64, u32)> = Vec::with_capacity(table.len());
    let mut heading = UnitQuaternion::identity();
    for k in 1.. {
        let t = first.t_s + k as f64 * plan.period_s;
        if t > last.t_s {
            break;
        }
        let Some(at) = interpolate(reference, t, plan.max_reference_gap_s, &mut cursor) else {
            continue;
        };
        // The attitude that orients the field of regard (and body directions).
        if let Some(q) = at.att_b_to_n {
            heading = q;
        } else if let Some(q) = attitude_from_motion(&at.vel_ned_mps, 0.5) {
            heading = q;
        }
        let pose = nav_pose(&at.nav_state(heading));
        let forward_ned = heading * Vector3::x();
        in_view.clear();
        for (id, lm) in table.iter() {
            let Ok(los) = sighting_model::line_of_sight(&at.pos, lm) else {
                continue;
            };
            let cos_off = forward_ned.dot(&los.los_ned_m) / los.range_m;
            if los.range_m >= plan.min_range_m
                && los.range_m <= plan.max_range_m
                && (plan.field_of_regard_deg >= 180.0 || cos_off >= cos_for)
            {
                in_view.push((los.range_m, id));
            }
        }
        in_view.sort_by(|a, b| a.0.total_cmp(&b.0));
        in_view.truncate(plan.max_per_epoch);
        written.min_per_epoch = written.min_per_epoch.min(in_view.len());
        if in_view.is_empty() {
            written.empty_epochs += 1;
            continue;
        }
        // Landmarks in id order within an epoch (the table's order).
        in_view.sort_by_key(|&(_, id)| id);
        for &(_, id) in &in_view {
            let Some(lm) = table.get(id) else { continue };
            let nw: f64 = rng.sample(StandardNormal);
            let nh: f64 = rng.sample(StandardNormal);
            let noise = Vector2::new(nw, nh) * plan.sigma_m;
            let u = sighting_model::los_from_truth(&pose, lm, frame, &noise)
                .map_err(|source| SimError::Sighting { t_s: t, source })?;
            writeln!(
                out,
                "{t:e},{id},{},{:e},{:e},{:e}",
                frame.as_str(),
                u.x,
                u.y,
                u.z
            )
            .map_err(&wio)?;
            written.sightings += 1;
        }
        written.epochs += 1;
    }
    if written.min_per_epoch == usize::MAX {
        written.min_per_epoch = 0;
    }
    out.flush().map_err(&wio)?;
    Ok(written)
}

/// `count` landmarks placed around `reference`, seeded: each beside a random reference row, at a
/// random bearing, a horizontal distance uniform in `[min_range_m, max_range_m]`, and a height
/// from 0.1·distance below to 0.3·distance above the vehicle's (masts and buildings more than
/// pits). Ids 1..=count.
///
/// # Errors
/// [`SimError::ReferenceSpan`] for an empty reference, [`SimError::ScenarioInvalid`] for bad
/// ranges.
pub fn landmarks_around(
    reference: &[ReferenceRow],
    count: usize,
    min_range_m: f64,
    max_range_m: f64,
    seed: u64,
) -> Result<Vec<LandmarkEntry>, SimError> {
    if reference.is_empty() {
        return Err(SimError::ReferenceSpan {
            t_s: 0.0,
            what: "the reference trajectory is empty",
        });
    }
    if !(min_range_m.is_finite()
        && min_range_m > 0.0
        && max_range_m > min_range_m
        && max_range_m.is_finite())
    {
        return Err(SimError::invalid(
            "landmark range",
            "must be 0 < min < max, finite",
            (min_range_m, max_range_m),
        ));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::with_capacity(count);
    for id in 1..=count {
        let row = &reference[rng.random_range(0..reference.len())];
        let bearing = rng.random_range(0.0..std::f64::consts::TAU);
        let d = rng.random_range(min_range_m..max_range_m);
        let up = rng.random_range(-0.1 * d..0.3 * d);
        let (rn, re) = ins_errors::earth::radii_of_curvature_m(row.pos.lat_rad);
        let lat = row.pos.lat_rad + d * bearing.cos() / (rn + row.pos.alt_m);
        let lon =
            row.pos.lon_rad + d * bearing.sin() / ((re + row.pos.alt_m) * row.pos.lat_rad.cos());
        let g = Geodetic {
            lat_rad: lat,
            lon_rad: lon,
            alt_m: row.pos.alt_m + up,
        };
        out.push(LandmarkEntry {
            id: id as u32,
            lat_deg: g.lat_rad.to_degrees(),
            lon_deg: g.lon_rad.to_degrees(),
            alt_m: g.alt_m,
        });
    }
    Ok(out)
}
