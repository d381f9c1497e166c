//! The candidate pixels and their index by row (module `candidates`, `chosen_fit`).

use super::scenes::*;
use super::*;

#[test]
fn a_chosen_lines_fit_on_the_pixels_near_it_equals_the_fit_on_all_of_them() {
    // The fit of a chosen line reads only the candidate pixels near the line
    // (`fit_chosen_line`); it must be the fit on all of them, bit for bit, and leave the same
    // pixels of the line's band for `install`. Lines swept across frames with clutter (a
    // crosswalk, a kerb) take both paths: the pixels near the line, and the full set where a
    // refit reaches a pixel left out.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    let frames = [
        two_marks(320, 240),
        crosswalk(320, 240, true),
        kerb_right(320, 240, false, 0.0),
    ];
    let (mut near, mut full) = (0, 0);
    for frame in &frames {
        let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
        tracker.track(frame).expect("a frame");
        // The buffers hold the last search's pixels; search those rows again.
        search_roi(&mut tracker, &image_of(frame));
        let params = tracker.setup.init_params;
        let (top, bottom) = tracker.setup.roi;
        let mid = 0.5 * (top + bottom) as f64;
        let in_band = |t: &LaneTracker, line: &hough_init::HoughLine| -> Vec<(f32, f32)> {
            let (s, c) = line.theta_rad.sin_cos();
            t.init
                .index
                .candidates
                .iter()
                .copied()
                .filter(|&(x, y)| {
                    (f64::from(x) * c + f64::from(y) * s - line.rho_px).abs() <= params.band_px
                })
                .collect()
        };
        for class in [EdgeClass::LeftLane, EdgeClass::RightLane] {
            for theta_deg in (-60..=60).step_by(4) {
                for col in (20..320).step_by(12) {
                    let theta_rad = f64::from(theta_deg).to_radians();
                    let line = hough_init::HoughLine {
                        rho_px: f64::from(col) * theta_rad.cos() + mid * theta_rad.sin(),
                        theta_rad,
                        votes: 0,
                    };
                    let (setup, edges, index) =
                        (&tracker.setup, &tracker.edges, &mut tracker.init.index);
                    let roi = setup.roi;
                    let fit = index.fit_chosen_line(edges, class, line, roi, setup);
                    let kept = in_band(&tracker, &line);
                    let (setup, edges, index) =
                        (&tracker.setup, &tracker.edges, &mut tracker.init.index);
                    let took_near = matches!(
                        index.fit_chosen_line_near(edges, class, line, roi, setup),
                        Ok(Some(_))
                    );
                    index.fill(edges, class, setup);
                    let all = hough_init::fit_around_line(&index.candidates, line, &params);
                    assert_eq!(fit, all, "class {class:?}, θ {theta_deg}°, column {col}");
                    if fit.is_ok() {
                        assert_eq!(kept, in_band(&tracker, &line));
                        if took_near {
                            near += 1;
                        } else {
                            full += 1;
                        }
                    }
                }
            }
        }
    }
    assert!(
        near > 100 && full > 5,
        "fits on the pixels near the line {near}, on all {full}"
    );
}

/// `has_candidates` says what `fill_candidates` would give — at least `min` pixels that count
/// as the class — without filling: both classes, `min` on both sides of the filled count, the
/// paired pixels counted 0–4 times (`gradient.stripe_paired_votes`), on frames with stripes,
/// a crosswalk and a kerb.
#[test]
fn has_candidates_agrees_with_the_candidates_filled() {
    let frames = [
        two_marks(320, 240),
        crosswalk(320, 240, true),
        kerb_right(320, 240, false, 0.0),
    ];
    let mut paired_counted = 0;
    for votes in 0..=4u8 {
        let mut cfg = TrackerConfig::default_preset().expect("the default preset");
        cfg.gradient.stripe_paired_votes = votes;
        for frame in &frames {
            let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
            search_roi(&mut tracker, &image_of(frame));
            let (setup, edges, index) = (&tracker.setup, &tracker.edges, &mut tracker.init.index);
            for class in [EdgeClass::LeftLane, EdgeClass::RightLane] {
                index.fill(edges, class, setup);
                let n = index.candidates.len();
                let edges_alone = edges
                    .edges
                    .pixels()
                    .iter()
                    .filter(|p| counts_as(p, class, setup.near_vertical_either_class()))
                    .count();
                paired_counted += usize::from(n > edges_alone);
                for min in [
                    0,
                    1,
                    edges_alone,
                    edges_alone + 1,
                    n.saturating_sub(1),
                    n,
                    n + 1,
                    2 * n + 5,
                ] {
                    assert_eq!(
                        index.has(edges, class, min, setup),
                        n >= min,
                        "votes {votes}, {class:?}, {n} candidates, min {min}"
                    );
                }
            }
        }
    }
    assert!(
        paired_counted >= 12,
        "paired pixels added candidates {paired_counted} times"
    );
}

/// The branch-free append of one class's pixels keeps exactly those pixels, in their order,
/// after the points already there, and within the room it documents (`pixels.len() + 1`
/// beyond the points held) it does not allocate.
#[test]
fn the_branch_free_append_keeps_one_class_in_order_without_allocating() {
    use vision_gradient::{EdgeClass, EdgePixel};
    let mut state = 0x9E37_79B9_u32;
    let pixels: Vec<EdgePixel> = (0..200u16)
        .map(|i| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            EdgePixel {
                col_px: i,
                row_px: 239 - i / 40,
                magnitude: 100,
                class: if state.is_multiple_of(3) {
                    EdgeClass::LeftLane
                } else {
                    EdgeClass::RightLane
                },
                gx: 50,
            }
        })
        .collect();
    for class in [EdgeClass::LeftLane, EdgeClass::RightLane] {
        let want: Vec<(f32, f32)> = [(-1.0, -1.0)]
            .into_iter()
            .chain(
                pixels
                    .iter()
                    .filter(|p| p.class == class)
                    .map(|p| (f32::from(p.col_px), f32::from(p.row_px))),
            )
            .collect();
        assert!(want.len() > 40 && want.len() < 160, "both classes drawn");
        let mut points = Vec::with_capacity(1 + pixels.len() + 1);
        points.push((-1.0, -1.0));
        let (_, allocations) = allocations_in(|| {
            crate::tracker::candidates::extend_with_class(&mut points, &pixels, class, 0)
        });
        assert_eq!(allocations, 0);
        assert_eq!(points, want);
    }
}

#[test]
fn unpaired_pixels_count_one_steps_worth_a_row_in_the_row_coverage() {
    // The row table filled by hand around the vertical curve x = 100 over the ROI rows: each
    // row holds `pixels` as (column, weight), weight 3 = a paired pixel (the default's
    // `stripe_paired_votes`), 1 = an unpaired one.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert_eq!(cfg.gradient.stripe_paired_votes, 3);
    let mut tracker = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let (top, bottom) = tracker.setup.roi;
    let rows = (bottom - top) as f64;
    let line = Parabola {
        a1: 0.0,
        a2: 0.0,
        a3: 100.0,
    };
    let mut coverage = |pixels: &[(u16, u16)]| {
        let index = &mut tracker.init.index;
        index.by_row.clear();
        index.row_start.fill(0);
        for r in 0..tracker.setup.height {
            if (top..bottom).contains(&r) {
                index.by_row.extend_from_slice(pixels);
            }
            index.row_start[r + 1] = index.by_row.len() as u32;
        }
        index.row_coverage(&line, (top, bottom), &tracker.setup)
    };
    // A bright stripe: its two paired sides, 6 a row (the row cap).
    assert_eq!(coverage(&[(98, 3), (102, 3)]), 6.0 * rows);
    // A single step: one unpaired pixel a row.
    assert_eq!(coverage(&[(100, 1)]), rows);
    // Texture on the curve: five unpaired pixels a row count as two (they counted 5 before).
    assert_eq!(
        coverage(&[(98, 1), (99, 1), (100, 1), (101, 1), (102, 1)]),
        2.0 * rows
    );
    // A stripe with unpaired texture around it keeps its 6; texture beside the curve (12 px
    // off, the background bands) is capped alike: 4 unpaired a side count 2, and the stripe
    // keeps 6 − (2 + 2)/2 = 4 a row (6 − (4 + 4)/2 = 2 before).
    assert_eq!(
        coverage(&[(97, 1), (98, 3), (102, 3), (103, 1)]),
        6.0 * rows
    );
    let beside = [
        (86, 1),
        (87, 1),
        (88, 1),
        (89, 1),
        (98, 3),
        (102, 3),
        (111, 1),
        (112, 1),
        (113, 1),
        (114, 1),
    ];
    assert_eq!(coverage(&beside), 4.0 * rows);
}

#[test]
fn one_frames_stripe_pairs_do_not_weigh_the_next_frames_pixels() {
    // The paired pixels of a frame are marked in a bit mask for the initialisation's weights
    // and the mask is cleared after use; a bit left set would count an unpaired pixel at the
    // same place on a later frame as paired (3 votes, not a step's share) and change its
    // candidates' support.
    let cfg = TrackerConfig::default_preset().expect("the default preset");
    assert!(cfg.gradient.stripe_paired_votes > 1);
    let (marks, road) = (two_marks(320, 240), road_between_marks(320, 240));
    let candidates_on_road = |tracker: &mut LaneTracker| {
        tracker.reset();
        tracker.track(&road).expect("a frame");
        tracker.init_candidates().to_vec()
    };
    let mut fresh = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    let alone = candidates_on_road(&mut fresh);
    assert!(!alone.is_empty(), "the road's edges give candidates");
    let mut used = LaneTracker::new(&cfg, Estimator::Kif, 320, 240).expect("a tracker");
    used.track(&marks).expect("a frame");
    assert!(
        used.init_candidates().iter().any(|c| c.chosen.is_some()),
        "the marks were initialised (their sides paired)"
    );
    let after_marks = candidates_on_road(&mut used);
    assert_eq!(after_marks, alone);
    // And again, with the marks' frame in between.
    used.reset();
    used.track(&marks).expect("a frame");
    assert_eq!(candidates_on_road(&mut used), alone);
}
