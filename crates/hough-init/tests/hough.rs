//! Hough transform: round trip on drawn lines, band restriction, workspace reuse, errors.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

mod common;

use common::{clutter, draw_line};
use hough_init::{
    AngleBand, HoughError, HoughLine, HoughParams, HoughWorkspace, LaneInitParams, Point, PointSet,
};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

const W: usize = 320;
const H: usize = 240;

/// Angular difference of two line normals, degrees, modulo 180°.
fn angle_diff_deg(a_deg: f64, b_deg: f64) -> f64 {
    let d = (a_deg - b_deg).rem_euclid(180.0);
    d.min(180.0 - d)
}

struct Case {
    theta_deg: f64,
    points: Vec<Point>,
    mid: (f64, f64),
    band: AngleBand,
}

/// A line at `theta_deg` through `(anchor_frac·W, 0.75·H)`, rows ≥ 0.4·H, plus clutter.
fn make_case(
    theta_deg: f64,
    anchor_frac: f64,
    sigma_px: f64,
    clutter_frac: f64,
    seed: u64,
) -> Case {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let line = draw_line(
        W,
        H,
        theta_deg,
        anchor_frac * W as f64,
        0.75 * H as f64,
        0.4 * H as f64,
        sigma_px,
        &mut rng,
    );
    let n_clutter = (clutter_frac * line.points.len() as f64).round() as usize;
    let mut points = line.points;
    points.extend(clutter(W, H, n_clutter, &mut rng));
    let band = if theta_deg > 0.0 {
        AngleBand::LEFT_LANE
    } else {
        AngleBand::RIGHT_LANE
    };
    Case {
        theta_deg,
        points,
        mid: line.mid,
        band,
    }
}

fn assert_found(case: &Case, found: &HoughLine, what: &str) {
    let dtheta = angle_diff_deg(found.theta_deg(), case.theta_deg);
    let dist = found.signed_distance_px(case.mid.0, case.mid.1).abs();
    assert!(
        dtheta <= 1.0,
        "{what}: θ off by {dtheta}° (true {}°, found {}°)",
        case.theta_deg,
        found.theta_deg()
    );
    assert!(
        dist <= 1.0,
        "{what}: segment midpoint {dist} px from the found line (θ {}°)",
        case.theta_deg
    );
}

fn proptest_config() -> Config {
    Config {
        cases: 64,
        rng_seed: RngSeed::Fixed(0x4f75_6768),
        failure_persistence: None,
        ..Config::default()
    }
}

proptest! {
    #![proptest_config(proptest_config())]

    /// A rasterised line with noise σ ≤ 0.5 px and up to 30 % uniform clutter is found within
    /// 1° and within 1 px (perpendicular distance of the drawn segment's midpoint).
    #[test]
    fn drawn_line_is_found_within_a_pixel_and_a_degree(
        abs_theta in 17.0f64..73.0,
        left in any::<bool>(),
        anchor_frac in 0.3f64..0.7,
        sigma_px in 0.0f64..=0.5,
        clutter_frac in 0.0f64..=0.3,
        seed in any::<u64>(),
    ) {
        let theta_deg = if left { abs_theta } else { -abs_theta };
        let case = make_case(theta_deg, anchor_frac, sigma_px, clutter_frac, seed);
        let mut ws = HoughWorkspace::new(W, H, HoughParams::default()).unwrap();
        let found = ws.find_line(&case.points, &case.band).unwrap();
        assert_found(&case, &found, "default params");
    }
}

/// Every combination of the optional peak-picking stages still meets the round-trip tolerance.
#[test]
fn round_trip_holds_with_smoothing_and_refinement_switched_off() {
    for (smoothing, refine) in [(false, false), (false, true), (true, false), (true, true)] {
        let params = HoughParams {
            peak_smoothing: smoothing,
            subbin_refinement: refine,
            ..HoughParams::default()
        };
        let mut ws = HoughWorkspace::new(W, H, params).unwrap();
        for (i, theta) in [-60.0, -41.3, -22.0, 20.0, 37.7, 58.9]
            .into_iter()
            .enumerate()
        {
            let case = make_case(theta, 0.5, 0.5, 0.3, 100 + i as u64);
            let found = ws.find_line(&case.points, &case.band).unwrap();
            assert_found(
                &case,
                &found,
                &format!("smoothing {smoothing}, refine {refine}"),
            );
        }
    }
}

/// Sub-bin refinement must not make things worse on average: mean |Δθ| over many noiseless
/// lines at off-grid angles is smaller with refinement than without.
#[test]
fn subbin_refinement_reduces_mean_angle_error() {
    let mut err = [0.0f64; 2];
    for (j, refine) in [false, true].into_iter().enumerate() {
        let params = HoughParams {
            subbin_refinement: refine,
            theta_step_deg: 1.0,
            ..HoughParams::default()
        };
        let mut ws = HoughWorkspace::new(W, H, params).unwrap();
        for i in 0..40 {
            let theta = 20.25 + 0.77 * f64::from(i);
            let case = make_case(theta, 0.5, 0.0, 0.0, 7);
            let found = ws.find_line(&case.points, &case.band).unwrap();
            err[j] += angle_diff_deg(found.theta_deg(), theta);
        }
    }
    assert!(
        err[1] < err[0],
        "mean |Δθ| with refinement {} ≥ without {}",
        err[1] / 40.0,
        err[0] / 40.0
    );
}

/// Only the lane's band is searched: a longer line outside the band loses to a shorter one
/// inside it, and the returned θ lies in the band.
#[test]
fn peak_is_restricted_to_the_angle_band() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    // Strong right-lane line (θ = −45°) over many rows, weak left-lane line (θ = +40°).
    let strong = draw_line(W, H, -45.0, 200.0, 180.0, 0.0, 0.0, &mut rng);
    let weak = draw_line(W, H, 40.0, 100.0, 200.0, 160.0, 0.0, &mut rng);
    assert!(strong.points.len() > 2 * weak.points.len());
    let mut points = strong.points.clone();
    points.extend(weak.points.iter().copied());
    let mut ws = HoughWorkspace::new(W, H, HoughParams::default()).unwrap();

    let left = ws.find_line(&points, &AngleBand::LEFT_LANE).unwrap();
    assert!(AngleBand::LEFT_LANE.contains_deg(left.theta_deg()));
    assert!(
        angle_diff_deg(left.theta_deg(), 40.0) <= 1.0,
        "left found {}°",
        left.theta_deg()
    );
    assert!(left.signed_distance_px(weak.mid.0, weak.mid.1).abs() <= 1.0);

    let right = ws.find_line(&points, &AngleBand::RIGHT_LANE).unwrap();
    assert!(
        angle_diff_deg(right.theta_deg(), -45.0) <= 1.0,
        "right found {}°",
        right.theta_deg()
    );

    // A narrow band that excludes both lines cannot return either.
    let narrow = AngleBand::new(60.0, 70.0);
    let other = ws.find_line(&points, &narrow).unwrap();
    assert!(narrow.contains_deg(other.theta_deg()));
}

/// Reusing a workspace gives the same answer as a fresh one (stale votes are cleared), for
/// overlapping and disjoint bands in any order.
#[test]
fn reused_workspace_matches_fresh_workspace() {
    let a = make_case(35.0, 0.4, 0.5, 0.3, 11);
    let b = make_case(-50.0, 0.6, 0.5, 0.3, 12);
    let wide = AngleBand::new(-80.0, 80.0);
    let fresh = |points: &[Point], band: &AngleBand| {
        HoughWorkspace::new(W, H, HoughParams::default())
            .unwrap()
            .find_line(points, band)
            .unwrap()
    };
    let mut ws = HoughWorkspace::new(W, H, HoughParams::default()).unwrap();
    for (points, band) in [
        (&b.points, &wide),
        (&a.points, &a.band),
        (&b.points, &b.band),
        (&a.points, &wide),
        (&a.points, &a.band),
    ] {
        assert_eq!(ws.find_line(points, band).unwrap(), fresh(points, band));
    }
}

/// The reported votes equal an independent count: the number of points whose ρ, recomputed in
/// f64 at the peak's θ bin, rounds to the same bin (bin edges excluded for robustness).
#[test]
fn reported_votes_match_an_independent_count() {
    let params = HoughParams {
        peak_smoothing: false,
        subbin_refinement: false,
        ..HoughParams::default()
    };
    let case = make_case(-33.0, 0.5, 0.3, 0.2, 21);
    let mut ws = HoughWorkspace::new(W, H, params).unwrap();
    let line = ws.find_line(&case.points, &case.band).unwrap();
    // Without refinement θ is a bin centre and ρ (about the image centre) a multiple of Δρ.
    let (cx, cy) = ((W as f64 - 1.0) / 2.0, (H as f64 - 1.0) / 2.0);
    let (s, c) = line.theta_rad.sin_cos();
    let rho_c = line.rho_px - cx * c - cy * s;
    let mut inside = 0u32;
    let mut near_edge = 0u32;
    for p in &case.points {
        let d = (p.col_px - cx) * c + (p.row_px - cy) * s - rho_c;
        if (d.abs() - 0.5).abs() < 1e-4 {
            near_edge += 1;
        } else if d.abs() < 0.5 {
            inside += 1;
        }
    }
    assert!(
        line.votes >= inside && line.votes <= inside + near_edge,
        "votes {} vs count {inside} (+{near_edge})",
        line.votes
    );
    assert!(inside > 20);
}

#[test]
fn workspace_rejects_bad_sizes_and_params() {
    assert!(matches!(
        HoughWorkspace::new(0, 240, HoughParams::default()),
        Err(HoughError::InvalidImageSize { width_px: 0, .. })
    ));
    assert!(matches!(
        HoughWorkspace::new(320, 100_000, HoughParams::default()),
        Err(HoughError::InvalidImageSize { .. })
    ));
    for (params, field) in [
        (
            HoughParams {
                theta_step_deg: 0.0,
                ..HoughParams::default()
            },
            "theta_step_deg",
        ),
        (
            HoughParams {
                theta_step_deg: f64::NAN,
                ..HoughParams::default()
            },
            "theta_step_deg",
        ),
        (
            HoughParams {
                rho_step_px: -1.0,
                ..HoughParams::default()
            },
            "rho_step_px",
        ),
        (
            HoughParams {
                rho_step_px: f64::INFINITY,
                ..HoughParams::default()
            },
            "rho_step_px",
        ),
    ] {
        match HoughWorkspace::new(W, H, params) {
            Err(HoughError::InvalidParam { field: f, .. }) => assert_eq!(f, field),
            other => panic!("expected InvalidParam({field}), got {other:?}"),
        }
    }
    let fine = HoughParams {
        theta_step_deg: 0.01,
        rho_step_px: 0.1,
        ..HoughParams::default()
    };
    assert!(matches!(
        HoughWorkspace::new(4000, 4000, fine),
        Err(HoughError::AccumulatorTooLarge { .. })
    ));
}

#[test]
fn find_line_rejects_bad_bands_and_points() {
    let mut ws = HoughWorkspace::new(W, H, HoughParams::default()).unwrap();
    let pts = [
        Point::new(10.0, 10.0),
        Point::new(20.0, 30.0),
        Point::new(30.0, 50.0),
    ];
    for band in [
        AngleBand::new(30.0, 30.0),
        AngleBand::new(40.0, 20.0),
        AngleBand::new(-95.0, 0.0),
        AngleBand::new(0.0, f64::NAN),
        AngleBand::new(30.1, 30.2), // no bin centre at Δθ = 0.5°
    ] {
        assert!(
            matches!(
                ws.find_line(&pts, &band),
                Err(HoughError::InvalidBand { .. })
            ),
            "band {band:?} accepted"
        );
    }
    let mut bad = pts.to_vec();
    bad[1].row_px = f64::NAN;
    assert!(matches!(
        ws.find_line(&bad, &AngleBand::LEFT_LANE),
        Err(HoughError::NonFinitePoint { index: 1, .. })
    ));
    let mut out = pts.to_vec();
    out[2].col_px = W as f64; // beyond the last pixel's right edge (W − 0.5)
    assert!(matches!(
        ws.find_line(&out, &AngleBand::LEFT_LANE),
        Err(HoughError::PointOutsideImage { index: 2, .. })
    ));
    assert!(matches!(
        ws.find_line(&pts[..1], &AngleBand::LEFT_LANE),
        Err(HoughError::TooFewPoints {
            set: PointSet::Candidates,
            found: 1,
            required: 2
        })
    ));
    // Image corners (pixel edges) are accepted.
    let corners = [
        Point::new(-0.5, -0.5),
        Point::new(W as f64 - 0.5, H as f64 - 0.5),
    ];
    assert!(ws.find_line(&corners, &AngleBand::RIGHT_LANE).is_ok());
}

/// The line's helper methods agree with the normal form.
#[test]
fn line_helpers_follow_the_normal_form() {
    let line = HoughLine {
        rho_px: 100.0,
        theta_rad: 30f64.to_radians(),
        votes: 0,
    };
    for row in [0.0, 57.0, 239.0] {
        let col = line.col_at_row(row).unwrap();
        assert!(line.signed_distance_px(col, row).abs() < 1e-9);
    }
    // dx/dy = −tan θ.
    let slope = line.col_at_row(1.0).unwrap() - line.col_at_row(0.0).unwrap();
    assert!((slope + 30f64.to_radians().tan()).abs() < 1e-12);
    let horizontal = HoughLine {
        rho_px: 10.0,
        theta_rad: -std::f64::consts::FRAC_PI_2,
        votes: 0,
    };
    assert_eq!(horizontal.col_at_row(5.0), None);
}

/// Configs are strict: unknown fields are rejected, defaults fill missing ones, and values
/// survive a JSON round trip.
#[test]
fn configs_deny_unknown_fields_and_round_trip() {
    assert!(serde_json::from_str::<HoughParams>(r#"{"theta_step":0.5}"#).is_err());
    assert!(serde_json::from_str::<LaneInitParams>(r#"{"band":4}"#).is_err());
    assert!(serde_json::from_str::<AngleBand>(r#"{"min_deg":1,"max_deg":2,"x":3}"#).is_err());
    let p: HoughParams = serde_json::from_str(r#"{"rho_step_px":2.0}"#).unwrap();
    assert_eq!(
        p,
        HoughParams {
            rho_step_px: 2.0,
            ..HoughParams::default()
        }
    );
    let band: AngleBand = serde_json::from_str(r#"{"min_deg":10.0,"max_deg":80.0}"#).unwrap();
    assert!(band.validate().is_ok());
    assert!(matches!(
        AngleBand::new(10.0, -10.0).validate(),
        Err(HoughError::InvalidBand { .. })
    ));
    let l = LaneInitParams {
        band_px: 3.5,
        min_points: 25,
        refit_iterations: 2,
    };
    let back: LaneInitParams = serde_json::from_str(&serde_json::to_string(&l).unwrap()).unwrap();
    assert_eq!(back, l);
    for (l, field) in [
        (
            LaneInitParams {
                band_px: 0.0,
                ..LaneInitParams::default()
            },
            "band_px",
        ),
        (
            LaneInitParams {
                min_points: 2,
                ..LaneInitParams::default()
            },
            "min_points",
        ),
        (
            LaneInitParams {
                refit_iterations: 11,
                ..LaneInitParams::default()
            },
            "refit_iterations",
        ),
    ] {
        match l.validate() {
            Err(HoughError::InvalidParam { field: f, .. }) => assert_eq!(f, field),
            other => panic!("expected InvalidParam({field}), got {other:?}"),
        }
    }
}
