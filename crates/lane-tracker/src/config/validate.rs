//! The configuration's validation: every field checked once, on load, each error naming its
//! field (`TrackerError::ConfigField`), the ranges the components check themselves left to them.

use super::*;

impl TrackerConfig {
    /// Check every field's range; the error names the first offending field.
    pub fn validate(&self) -> Result<(), TrackerError> {
        let w = self.frame.working_width_px;
        check(
            w == 0 || (16..=16384).contains(&w),
            "frame.working_width_px",
            w,
            "must be 0 (the input's own size) or in 16..=16384 px",
        )?;
        let m = self.exposure.below_median_grey;
        check(
            m.is_finite() && (0.0..=255.0).contains(&m),
            "exposure.below_median_grey",
            m,
            "must be in 0..=255 grey levels (0: never)",
        )?;
        let n = self.denoise.above_noise_grey;
        check(
            n.is_finite() && (0.0..=255.0).contains(&n),
            "denoise.above_noise_grey",
            n,
            "must be in 0..=255 grey levels (0: never)",
        )?;
        // Stage I and II: the component crates' own checks, named by the TOML key.
        let g = &self.gradient;
        g.params().validate().map_err(gradient_field)?;
        for band in g.hough_bands() {
            band.validate().map_err(init_field)?;
        }
        self.init.hough_params().validate().map_err(init_field)?;
        self.init.lane_params().validate().map_err(init_field)?;
        let i = &self.init;
        // The message names the bound.
        const _: () = assert!(crate::tracker::MAX_CANDIDATE_LINES == 8);
        check(
            i.candidate_lines <= crate::tracker::MAX_CANDIDATE_LINES,
            "init.candidate_lines",
            i.candidate_lines,
            "must be in 0..=8",
        )?;
        check(
            i.candidate_separation_deg.is_finite() && i.candidate_separation_deg >= 0.0,
            "init.candidate_separation_deg",
            i.candidate_separation_deg,
            "must be finite and ≥ 0 degrees",
        )?;
        check(
            i.candidate_separation_px.is_finite() && i.candidate_separation_px >= 0.0,
            "init.candidate_separation_px",
            i.candidate_separation_px,
            "must be finite and ≥ 0 px",
        )?;
        check(
            (0.0..=90.0).contains(&i.orientation_tolerance_deg),
            "init.orientation_tolerance_deg",
            i.orientation_tolerance_deg,
            "must be in [0, 90] degrees (0: every pixel votes across its band)",
        )?;
        i.ego_pair.validate().map_err(init_field)?;
        check(
            g.stripe_max_width_px <= 200,
            "gradient.stripe_max_width_px",
            g.stripe_max_width_px,
            "must be in 0..=200 px",
        )?;
        check(
            !self.init.kerb_foot || g.stripe_max_width_px >= 4,
            "init.kerb_foot",
            self.init.kerb_foot,
            "needs gradient.stripe_max_width_px ≥ 4 px (a kerb's face is read up to it)",
        )?;
        check(
            !self.init.stripe_trace || g.stripe_max_width_px >= 2,
            "init.stripe_trace",
            self.init.stripe_trace,
            "needs gradient.stripe_max_width_px ≥ 2 px (the widest stripe it follows)",
        )?;
        check(
            g.periodic_min_stripes == 0 || (3..=16).contains(&g.periodic_min_stripes),
            "gradient.periodic_min_stripes",
            g.periodic_min_stripes,
            "must be 0 (off) or in 3..=16 (a double line is two stripes)",
        )?;
        check(
            (1..=200).contains(&g.periodic_max_width_px),
            "gradient.periodic_max_width_px",
            g.periodic_max_width_px,
            "must be in 1..=200 px",
        )?;
        check(
            g.stripe_paired_votes <= 4,
            "gradient.stripe_paired_votes",
            g.stripe_paired_votes,
            "must be in 0..=4",
        )?;
        let r = &self.roi;
        check(
            (0.0..1.0).contains(&r.top_row_fraction),
            "roi.top_row_fraction",
            r.top_row_fraction,
            "must be in [0, 1)",
        )?;
        check(
            r.bottom_row_fraction > r.top_row_fraction && r.bottom_row_fraction <= 1.0,
            "roi.bottom_row_fraction",
            r.bottom_row_fraction,
            "must be in (top_row_fraction, 1]",
        )?;
        if let Some(f) = r.fallback_top_row_fraction {
            check(
                (0.0..r.top_row_fraction).contains(&f),
                "roi.fallback_top_row_fraction",
                f,
                "must be in [0, top_row_fraction)",
            )?;
        }
        let t = &self.track;
        check(
            (1..=200).contains(&t.window_half_width_px),
            "track.window_half_width_px",
            t.window_half_width_px,
            "must be in 1..=200 px",
        )?;
        check(
            t.refine_window_half_width_px <= 200,
            "track.refine_window_half_width_px",
            t.refine_window_half_width_px,
            "must be in 0..=200 px (0: window_half_width_px)",
        )?;
        check(
            t.refine_passes <= 5,
            "track.refine_passes",
            t.refine_passes,
            "must be in 0..=5",
        )?;
        check(
            t.revalidate_every_frames <= 100_000,
            "track.revalidate_every_frames",
            t.revalidate_every_frames,
            "must be in 0..=100000 frames (0: no period)",
        )?;
        check(
            t.revalidate_keep_factor >= 1.0 && t.revalidate_keep_factor.is_finite(),
            "track.revalidate_keep_factor",
            t.revalidate_keep_factor,
            "must be finite and >= 1",
        )?;
        check(
            (0.0..=90.0).contains(&t.orientation_tolerance_deg),
            "track.orientation_tolerance_deg",
            t.orientation_tolerance_deg,
            "must be in [0, 90] degrees (0: every window pixel)",
        )?;
        check(
            t.inlier_half_width_px > 0.0 && t.inlier_half_width_px.is_finite(),
            "track.inlier_half_width_px",
            t.inlier_half_width_px,
            "must be finite and > 0 px",
        )?;
        check(
            (3..=1000).contains(&t.max_points_per_lane),
            "track.max_points_per_lane",
            t.max_points_per_lane,
            "must be in 3..=1000",
        )?;
        check(
            t.revalidate_below_points <= t.max_points_per_lane,
            "track.revalidate_below_points",
            t.revalidate_below_points,
            "must be in 0..=max_points_per_lane points (0: the period only)",
        )?;
        check(
            t.reinit_min_points >= 3 && t.reinit_min_points <= t.max_points_per_lane,
            "track.reinit_min_points",
            t.reinit_min_points,
            "must be in 3..=max_points_per_lane",
        )?;
        check(
            t.lost_after_frames >= 1,
            "track.lost_after_frames",
            t.lost_after_frames,
            "must be ≥ 1",
        )?;
        check(
            t.max_jump_px > 0.0 && t.max_jump_px.is_finite(),
            "track.max_jump_px",
            t.max_jump_px,
            "must be finite and > 0 px",
        )?;
        check(
            t.min_lane_separation_px >= 0.0 && t.min_lane_separation_px.is_finite(),
            "track.min_lane_separation_px",
            t.min_lane_separation_px,
            "must be finite and ≥ 0 px",
        )?;
        let f = &self.filter;
        check(
            f.q_sigma_px.iter().all(|s| s.is_finite() && *s > 0.0),
            "filter.q_sigma_px",
            format!("{:?}", f.q_sigma_px),
            "each must be finite and > 0 px/frame",
        )?;
        check(
            f.r_sigma_px.is_finite() && f.r_sigma_px > 0.0,
            "filter.r_sigma_px",
            f.r_sigma_px,
            "must be finite and > 0 px",
        )?;
        check(
            f.p0_sigma_px.iter().all(|s| s.is_finite() && *s > 0.0),
            "filter.p0_sigma_px",
            format!("{:?}", f.p0_sigma_px),
            "each must be finite and > 0 px",
        )?;
        check(
            f.wrls_lambda > 0.0 && f.wrls_lambda <= 1.0,
            "filter.wrls_lambda",
            f.wrls_lambda,
            "must be in (0, 1]",
        )?;
        Ok(())
    }
}

/// A `vision-gradient` parameter error as the configuration field it came from (the
/// component's error kept as the source); a field this configuration does not set stays the
/// component's error.
fn gradient_field(e: GradientError) -> TrackerError {
    let field = match &e {
        GradientError::InvalidParam { field, .. } => match *field {
            "min_edge_angle_deg" => Some("gradient.min_edge_angle_deg"),
            "max_edge_angle_deg" => Some("gradient.max_edge_angle_deg"),
            "threshold.keep_fraction" => Some("gradient.adaptive_keep_fraction"),
            "threshold.min_magnitude" => Some("gradient.magnitude_threshold"),
            _ => None,
        },
        _ => None,
    };
    match field {
        Some(field) => TrackerError::ConfigGradient { field, source: e },
        None => TrackerError::Gradient(e),
    }
}

/// A `hough-init` parameter error (Hough, least-squares or ego-pair parameters; their field
/// names differ) as the configuration field it came from (the component's error kept as the
/// source); a field this configuration does not set stays the component's error. The Hough
/// band comes from the edge-angle band.
fn init_field(e: HoughError) -> TrackerError {
    let field = match &e {
        HoughError::InvalidParam { field, .. } => match *field {
            "theta_step_deg" => Some("init.theta_step_deg"),
            "rho_step_px" => Some("init.rho_step_px"),
            "band_px" => Some("init.band_half_width_px"),
            "min_points" => Some("init.min_points"),
            "refit_iterations" => Some("init.refit_iterations"),
            "min_width_frac" => Some("init.ego_pair.min_width_frac"),
            "max_width_frac" => Some("init.ego_pair.max_width_frac"),
            "centre_margin_frac" => Some("init.ego_pair.centre_margin_frac"),
            "max_top_width_ratio" => Some("init.ego_pair.max_top_width_ratio"),
            "centre_weight" => Some("init.ego_pair.centre_weight"),
            "width_weight" => Some("init.ego_pair.width_weight"),
            "lone_min_lean_deg" => Some("init.ego_pair.lone_min_lean_deg"),
            "meet_top_frac" => Some("init.ego_pair.meet_top_frac"),
            "min_support_frac" => Some("init.ego_pair.min_support_frac"),
            _ => None,
        },
        HoughError::InvalidBand { .. } => Some("gradient.min_edge_angle_deg"),
        _ => None,
    };
    match field {
        Some(field) => TrackerError::ConfigHough { field, source: e },
        None => TrackerError::Hough(e),
    }
}

fn field_err(field: &'static str, value: impl std::fmt::Display, reason: &str) -> TrackerError {
    TrackerError::ConfigField {
        field,
        value: value.to_string(),
        reason: reason.to_owned(),
    }
}

fn check(
    ok: bool,
    field: &'static str,
    value: impl std::fmt::Display,
    reason: &str,
) -> Result<(), TrackerError> {
    if ok {
        Ok(())
    } else {
        Err(field_err(field, value, reason))
    }
}
