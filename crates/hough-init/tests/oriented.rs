//! Orientation-restricted Hough vote (`HoughWorkspace::find_lines_oriented`): equal to the plain
//! transform when the tolerance covers every bin, votes only near each point's own normal, and
//! lifts a mark out of clutter that outvotes it in the plain transform; bad input is an error
//! naming the point or the parameter.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use hough_init::{AngleBand, HoughError, HoughLine, HoughParams, HoughWorkspace, OrientedPoint};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const W: usize = 320;
const H: usize = 240;
const NONE: HoughLine = HoughLine {
    rho_px: 0.0,
    theta_rad: 0.0,
    votes: 0,
};

fn workspace() -> HoughWorkspace {
    workspace_with_step(1.0)
}

fn workspace_with_step(theta_step_deg: f64) -> HoughWorkspace {
    HoughWorkspace::new(
        W,
        H,
        HoughParams {
            theta_step_deg,
            ..HoughParams::default()
        },
    )
    .unwrap()
}

/// Points of the line of normal angle `theta_deg` through `(x0, y0)` on rows `rows`, each
/// carrying the normal `normal_deg` (the line's own for a straight mark).
fn line(
    theta_deg: f64,
    x0: f64,
    y0: f64,
    rows: std::ops::Range<u32>,
    normal_deg: f32,
) -> Vec<OrientedPoint> {
    // Along the line dx/dy = −tan θ.
    let slope = -theta_deg.to_radians().tan();
    rows.map(|r| OrientedPoint {
        col_px: (x0 + slope * (f64::from(r) - y0)) as f32,
        row_px: r as f32,
        normal_deg,
        votes: 1,
    })
    .filter(|p| (0.0..W as f32 - 1.0).contains(&p.col_px))
    .collect()
}

/// `count` uniformly scattered points with uniformly random normals.
fn texture(count: usize, rng: &mut ChaCha8Rng) -> Vec<OrientedPoint> {
    (0..count)
        .map(|_| OrientedPoint {
            col_px: rng.random_range(0.0..W as f32 - 1.0),
            row_px: rng.random_range(0.4 * H as f32..H as f32 - 1.0),
            normal_deg: rng.random_range(-90.0..90.0),
            votes: 1,
        })
        .collect()
}

fn angle_diff_deg(a_deg: f64, b_deg: f64) -> f64 {
    let d = (a_deg - b_deg).rem_euclid(180.0);
    d.min(180.0 - d)
}

#[test]
fn a_tolerance_covering_every_bin_gives_the_plain_transforms_lines() {
    for seed in 0..6u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut points = line(35.0, 120.0, 180.0, 100..240, 35.0);
        points.extend(line(-50.0, 220.0, 200.0, 110..240, -50.0));
        points.extend(texture(400, &mut rng));
        // 0.7° does not divide 180°: the bins do not close the half circle exactly.
        for (step, band) in [
            (1.0, AngleBand::LEFT_LANE),
            (1.0, AngleBand::RIGHT_LANE),
            (0.7, AngleBand::new(-85.0, -75.0)),
            (0.7, AngleBand::LEFT_LANE),
        ] {
            let (mut plain, mut oriented) = ([NONE; 6], [NONE; 6]);
            let n_plain = workspace_with_step(step)
                .find_lines(&points, &band, 3.0, 8.0, &mut plain)
                .unwrap();
            let n_oriented = workspace_with_step(step)
                .find_lines_oriented(&points, &band, 90.0, 3.0, 8.0, &mut oriented)
                .unwrap();
            assert_eq!(n_plain, n_oriented, "seed {seed}, step {step}");
            assert_eq!(
                plain[..n_plain],
                oriented[..n_oriented],
                "seed {seed}, step {step}"
            );
        }
    }
}

#[test]
fn a_point_votes_only_within_the_tolerance_of_its_own_normal() {
    // Points on a 40° line that claim a 10° normal: with a 5° tolerance no vote reaches 40°.
    let points = line(40.0, 100.0, 200.0, 100..240, 10.0);
    let mut out = [NONE; 3];
    let n = workspace()
        .find_lines_oriented(&points, &AngleBand::new(0.5, 80.0), 5.0, 3.0, 8.0, &mut out)
        .unwrap();
    assert!(n > 0);
    for l in &out[..n] {
        let d = angle_diff_deg(l.theta_deg(), 10.0);
        assert!(
            d <= 6.0,
            "a line at {:.1}° from normals of 10°",
            l.theta_deg()
        );
    }
    // The plain transform finds the 40° line itself.
    let plain = workspace()
        .find_line(&points, &AngleBand::new(0.5, 80.0))
        .unwrap();
    assert!(angle_diff_deg(plain.theta_deg(), 40.0) < 1.0);
}

#[test]
fn a_mark_outvoted_by_texture_and_a_jagged_border_in_the_plain_transform_wins_the_oriented_one() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let band = AngleBand::new(1.0, 75.0);
    // The mark: 70 rows at 30°, its pixels' normals within ±4° of the truth.
    let mut points: Vec<OrientedPoint> = line(30.0, 140.0, 200.0, 170..240, 30.0)
        .into_iter()
        .map(|mut p| {
            p.normal_deg += rng.random_range(-4.0..4.0);
            p
        })
        .collect();
    // A jagged border: a longer 60° line whose pixels' normals alternate between the
    // horizontal and the vertical (the teeth of a puzzle mat), two pixels per row.
    for (k, p) in line(60.0, 200.0, 200.0, 100..240, 0.0)
        .into_iter()
        .enumerate()
    {
        for dx in [0.0, 1.0] {
            points.push(OrientedPoint {
                col_px: p.col_px + dx,
                normal_deg: if k % 2 == 0 { 0.0 } else { -89.0 },
                ..p
            });
        }
    }
    points.extend(texture(1500, &mut rng));
    let mut out = [NONE; 1];
    workspace()
        .find_lines(&points, &band, 3.0, 8.0, &mut out)
        .unwrap();
    assert!(
        angle_diff_deg(out[0].theta_deg(), 60.0) < 2.0,
        "the plain transform's best line is the border: {:.1}°",
        out[0].theta_deg()
    );
    workspace()
        .find_lines_oriented(&points, &band, 15.0, 3.0, 8.0, &mut out)
        .unwrap();
    assert!(
        angle_diff_deg(out[0].theta_deg(), 30.0) < 2.0,
        "the oriented transform's best line is the mark: {:.1}°",
        out[0].theta_deg()
    );
}

#[test]
fn normals_near_the_ends_of_the_range_wrap_modulo_180_degrees() {
    // A near-horizontal line of normal −88° is the line of normal 92° ≡ −88°; points claiming
    // 89.5° (≡ −90.5°) are within 3° of it and vote for it across the wrap.
    let points = (0..200)
        .map(|i| OrientedPoint {
            col_px: 20.0 + i as f32,
            row_px: 150.0 + (i as f32) * (2.0f32.to_radians().tan()),
            normal_deg: 89.5,
            votes: 1,
        })
        .collect::<Vec<_>>();
    let mut out = [NONE; 1];
    let n = workspace()
        .find_lines_oriented(
            &points,
            &AngleBand::new(-89.5, -80.0),
            3.0,
            3.0,
            8.0,
            &mut out,
        )
        .unwrap();
    assert_eq!(n, 1);
    assert!(
        angle_diff_deg(out[0].theta_deg(), -88.0) < 1.5,
        "{}",
        out[0].theta_deg()
    );
}

#[test]
fn bad_normals_tolerances_and_separations_are_errors_that_say_which() {
    let mut ws = workspace();
    let mut out = [NONE; 2];
    let mut points = line(30.0, 140.0, 200.0, 150..240, 30.0);
    for (bad, at) in [
        (f32::NAN, 3usize),
        (90.0, 5),
        (-90.5, 0),
        (f32::INFINITY, 7),
    ] {
        let mut p = points.clone();
        p[at].normal_deg = bad;
        match ws.find_lines_oriented(&p, &AngleBand::LEFT_LANE, 15.0, 3.0, 8.0, &mut out) {
            Err(HoughError::InvalidNormal { index, .. }) => assert_eq!(index, at),
            other => panic!("{bad}: {other:?}"),
        }
    }
    for tol in [-1.0, f64::NAN] {
        assert!(matches!(
            ws.find_lines_oriented(&points, &AngleBand::LEFT_LANE, tol, 3.0, 8.0, &mut out),
            Err(HoughError::InvalidParam {
                field: "tolerance_deg",
                ..
            })
        ));
    }
    assert!(matches!(
        ws.find_lines_oriented(&points, &AngleBand::LEFT_LANE, 15.0, -3.0, 8.0, &mut out),
        Err(HoughError::InvalidParam {
            field: "sep_theta_deg",
            ..
        })
    ));
    points[2].col_px = 1e6;
    assert!(matches!(
        ws.find_lines_oriented(&points, &AngleBand::LEFT_LANE, 15.0, 3.0, 8.0, &mut out),
        Err(HoughError::PointOutsideImage { index: 2, .. })
    ));
    assert!(matches!(
        ws.find_lines_oriented(
            &points[..1],
            &AngleBand::LEFT_LANE,
            15.0,
            3.0,
            8.0,
            &mut out
        ),
        Err(HoughError::TooFewPoints { found: 1, .. })
    ));
    // Weighted votes that the counters (and the 3×3 smoothed peak search) cannot hold.
    let heavy = vec![
        OrientedPoint {
            col_px: 100.0,
            row_px: 200.0,
            normal_deg: 30.0,
            votes: u16::MAX,
        };
        (u32::MAX / 3 / u32::from(u16::MAX)) as usize + 1
    ];
    assert!(matches!(
        ws.find_lines_oriented(&heavy, &AngleBand::LEFT_LANE, 15.0, 3.0, 8.0, &mut out),
        Err(HoughError::TooManyVotes { .. })
    ));
}

#[test]
fn a_point_with_k_votes_counts_as_the_point_repeated_k_times() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut points = line(35.0, 120.0, 180.0, 100..240, 35.0);
    points.extend(texture(300, &mut rng));
    // Every third point carries 3 votes in one list, and is repeated 3 times in the other.
    let mut weighted = points.clone();
    let mut repeated = points.clone();
    for (i, p) in points.iter().enumerate().filter(|(i, _)| i % 3 == 0) {
        weighted[i].votes = 3;
        repeated.extend([*p, *p]);
    }
    let (mut a, mut b) = ([NONE; 5], [NONE; 5]);
    let na = workspace()
        .find_lines_oriented(&weighted, &AngleBand::LEFT_LANE, 15.0, 3.0, 8.0, &mut a)
        .unwrap();
    let nb = workspace()
        .find_lines_oriented(&repeated, &AngleBand::LEFT_LANE, 15.0, 3.0, 8.0, &mut b)
        .unwrap();
    assert_eq!(a[..na], b[..nb]);
    assert!(a[0].votes > 0);
}
