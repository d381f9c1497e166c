//! `census_lanes` lists every scored ego label lane with the stage where it is lost, and
//! `StageCensus::count` counts them: a label on the
//! tracked mark is matched, a label where no mark is has no candidate and no edge near it, a
//! label a little beside a mark has no candidate but an edge near it, a label on a mark the
//! ego-pair choice passed over is "not chosen", a lane tracked from the previous frame is not
//! classified. The choice's bound takes a candidate only where it beats the output against the
//! labels, and its abstaining form drops a far lane. A frame four times as large (each pixel repeated 4 × 4, the labels mapped) is
//! classified as its working frame is: the same counts.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;

use lane_bench::labelled::{
    LabelSet, LabelSide, LaneCensus, LaneStage, ScoringRules, StageCensus, census_lanes,
    choice_bound_set, score_frame, track_label_set,
};
use lane_tracker::{Estimator, TrackerConfig};

const W: usize = 320;
const H: usize = 180;

fn left(y: f64) -> f64 {
    100.0 - 0.6 * (y - 179.0)
}
fn right(y: f64) -> f64 {
    220.0 + 0.6 * (y - 179.0)
}
/// A neighbour lane's mark right of the ego lane.
fn outer(y: f64) -> f64 {
    300.0 + 1.2 * (y - 179.0)
}

/// Bright marks 5 px wide on a dark floor along the given curves.
fn marks(curves: &[fn(f64) -> f64]) -> image::GrayImage {
    image::GrayImage::from_fn(W as u32, H as u32, |x, y| {
        let on = curves
            .iter()
            .any(|c| (f64::from(x) - c(f64::from(y))).abs() < 2.5);
        image::Luma([if on { 200 } else { 60 }])
    })
}

/// A label lane along `f` from row 100 down, one point per row, in the pixels of the frame
/// enlarged `scale` times (working pixel `c` centred on `scale·c + (scale − 1)/2`).
fn label(side: &str, f: fn(f64) -> f64, scale: u32) -> String {
    let (k, o) = (f64::from(scale), 0.5 * f64::from(scale - 1));
    let pts: Vec<String> = (100..H)
        .map(|y| format!("[{:.3}, {:.3}]", k * f(y as f64) + o, k * y as f64 + o))
        .collect();
    format!(r#"{{"side": "{side}", "points": [{}]}}"#, pts.join(", "))
}

/// A scene: the curves marked, and the left and right labels' sides and curves.
type Scene<'a> = (&'a [Curve], [(&'a str, Curve); 2]);
type Curve = fn(f64) -> f64;

/// Writes the census scenes (the frames of [`every_scored_label_lane_is_put_in_the_stage_where_it_is_lost`],
/// each pixel repeated `scale × scale` times, the labels mapped) into a fresh directory.
/// `tag` names the directory apart from another test's.
fn write_scenes(tag: &str, scale: u32) -> (PathBuf, LabelSet) {
    let dir: PathBuf = std::env::temp_dir().join(format!(
        "ita-nav-census-{}-{tag}-{scale}x",
        std::process::id()
    ));
    std::fs::create_dir_all(dir.join("frames")).unwrap();
    // Frame 0: labels on the two marks. Frame 1: the right label 40 px right of any mark.
    // Frame 2: a neighbour's mark too, and the right label on it. Frames 3 and 4: one clip of
    // two frames with the labels on the marks (the second frame is tracked, not initialised).
    // Frames 5 and 6: the right label 9 and 12 px right of the mark's centre line (its edge
    // 6.5 and 9.5 px away: beyond the TuSimple tolerance of 5 / cos(atan 0.6) = 5.8 px, within
    // the census's 5 + 16/2 = 13 px of an edge: the default's stripe width; at 4 × in input
    // pixels, 20 + 8 = 28 px would not reach frame 6's edge, 38 px away).
    let shifted: fn(f64) -> f64 = |y| right(y) + 40.0;
    let beside: fn(f64) -> f64 = |y| right(y) + 9.0;
    let farther: fn(f64) -> f64 = |y| right(y) + 12.0;
    let frames: [Scene; 7] = [
        (&[left, right], [("left", left), ("right", right)]),
        (&[left, right], [("left", left), ("right", shifted)]),
        (&[left, right, outer], [("left", left), ("right", outer)]),
        (&[left, right], [("left", left), ("right", right)]),
        (&[left, right], [("left", left), ("right", right)]),
        (&[left, right], [("left", left), ("right", beside)]),
        (&[left, right], [("left", left), ("right", farther)]),
    ];
    let clips = [0, 1, 2, 3, 3, 5, 6];
    let mut entries = Vec::new();
    for (i, (curves, lanes)) in frames.iter().enumerate() {
        let file = format!("frames/{i:04}.png");
        let small = marks(curves);
        let img = image::GrayImage::from_fn(W as u32 * scale, H as u32 * scale, |x, y| {
            *small.get_pixel(x / scale, y / scale)
        });
        img.save(dir.join(&file)).unwrap();
        let lanes = lanes.map(|(side, f)| label(side, f, scale));
        entries.push(format!(
            r#"{{"index": {i}, "file": "{file}", "clip": "c{}", "lanes": [{}]}}"#,
            clips[i],
            lanes.join(", ")
        ));
    }
    let json = format!(
        r#"{{"schema": 1, "set": "census", "kind": "road", "source": "rendered by the test",
            "licence": "none", "width": {}, "height": {}, "frames": [{}]}}"#,
        W as u32 * scale,
        H as u32 * scale,
        entries.join(", ")
    );
    std::fs::write(dir.join("labels.json"), json).unwrap();
    let set = LabelSet::load(&dir).unwrap();
    (dir, set)
}

#[test]
fn every_scored_label_lane_is_put_in_the_stage_where_it_is_lost() {
    let (dir, set) = write_scenes("stages", 1);
    let cfg = TrackerConfig::default_preset().unwrap();
    let rules = ScoringRules::default();
    let census = |frames| {
        StageCensus::count(&census_lanes(&dir, &set, &cfg, Estimator::Kif, frames, &rules).unwrap())
    };

    // Every class of every range, so a lane counted in a wrong class fails too.
    let counts = |matched, no_candidate, no_edge, not_chosen, not_classified| StageCensus {
        label_lanes: 2,
        matched,
        found_by_refinement: 0,
        no_candidate,
        no_edge_near_label: no_edge,
        not_chosen,
        lost_after_choice: 0,
        not_classified,
    };
    let first = census(0..1);
    assert_eq!(first, counts(2, 0, 0, 0, 0));
    let nowhere = census(1..2);
    assert_eq!(nowhere, counts(1, 1, 1, 0, 0));
    let passed_over = census(2..3);
    assert_eq!(passed_over, counts(1, 0, 0, 1, 0));
    // A tracked frame's lanes are not classified; its clip's first frame's are.
    let clip = census(3..5);
    assert_eq!(clip, counts(2, 0, 0, 0, 2));
    // Beside the mark: no candidate, but the mark's edge is near the label.
    let off = census(5..7);
    assert_eq!(
        off,
        StageCensus {
            label_lanes: 4,
            ..counts(2, 2, 0, 0, 0)
        }
    );
    // Ranges of separate clips add up.
    let all = census(0..7);
    let mut sum = StageCensus::default();
    for c in [first, nowhere, passed_over, clip, off] {
        sum.add(&c);
    }
    assert_eq!(all, sum);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn each_label_lane_is_listed_with_its_frame_side_and_stage() {
    let (dir, set) = write_scenes("lanes", 1);
    let cfg = TrackerConfig::default_preset().unwrap();
    let rules = ScoringRules::default();
    let lanes = census_lanes(&dir, &set, &cfg, Estimator::Kif, 0..7, &rules).unwrap();
    let (l, r) = (LabelSide::Left, LabelSide::Right);
    let want: Vec<LaneCensus> = [
        (0, l, LaneStage::Matched),
        (0, r, LaneStage::Matched),
        (1, l, LaneStage::Matched),
        (1, r, LaneStage::NoEdgeNearLabel),
        (2, l, LaneStage::Matched),
        (2, r, LaneStage::NotChosen),
        (3, l, LaneStage::Matched),
        (3, r, LaneStage::Matched),
        (4, l, LaneStage::NotClassified),
        (4, r, LaneStage::NotClassified),
        (5, l, LaneStage::Matched),
        (5, r, LaneStage::NoCandidate),
        (6, l, LaneStage::Matched),
        (6, r, LaneStage::NoCandidate),
    ]
    .into_iter()
    .map(|(position, side, stage)| LaneCensus {
        position,
        side,
        stage,
    })
    .collect();
    assert_eq!(lanes, want);
    // A range lists only its own frames.
    let part = census_lanes(&dir, &set, &cfg, Estimator::Kif, 2..4, &rules).unwrap();
    assert_eq!(part, want[4..8]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn stage_counts_nest_the_refinement_in_matched_and_the_missing_edge_in_no_candidate() {
    let lane = |stage| LaneCensus {
        position: 0,
        side: LabelSide::Left,
        stage,
    };
    let all = [
        LaneStage::Matched,
        LaneStage::FoundByRefinement,
        LaneStage::NoCandidate,
        LaneStage::NoEdgeNearLabel,
        LaneStage::NotChosen,
        LaneStage::LostAfterChoice,
        LaneStage::NotClassified,
    ]
    .map(lane);
    assert_eq!(
        StageCensus::count(&all),
        StageCensus {
            label_lanes: 6,
            matched: 2,
            found_by_refinement: 1,
            no_candidate: 2,
            no_edge_near_label: 1,
            not_chosen: 1,
            lost_after_choice: 1,
            not_classified: 1,
        }
    );
    // Names as serialised, one per stage.
    for l in &all {
        let json = serde_json::to_string(&l.stage).unwrap();
        assert_eq!(json, format!("\"{}\"", l.stage.name()));
    }
}

#[test]
fn a_frame_four_times_as_large_is_classified_as_its_working_frame() {
    let cfg = TrackerConfig::default_preset().unwrap();
    let rules = ScoringRules::default();
    let (small_dir, small) = write_scenes("large", 1);
    let (large_dir, large) = write_scenes("large", 4);
    for frames in [0..1, 1..2, 2..3, 3..5, 5..6, 6..7] {
        let at = |dir: &PathBuf, set: &LabelSet| {
            StageCensus::count(
                &census_lanes(dir, set, &cfg, Estimator::Kif, frames.clone(), &rules).unwrap(),
            )
        };
        assert_eq!(
            at(&large_dir, &large),
            at(&small_dir, &small),
            "frames {frames:?}"
        );
    }
    std::fs::remove_dir_all(&small_dir).unwrap();
    std::fs::remove_dir_all(&large_dir).unwrap();
}

#[test]
fn the_choice_bound_takes_a_candidate_only_where_it_beats_the_output() {
    let (dir, set) = write_scenes("bound", 1);
    let cfg = TrackerConfig::default_preset().unwrap();
    let rules = ScoringRules::default();
    let run = choice_bound_set(&dir, &set, &cfg, Estimator::Kif, &rules).unwrap();
    // The same run as the tracker's own.
    let output = track_label_set(&dir, &set, &cfg, Estimator::Kif)
        .unwrap()
        .predictions;
    assert_eq!(run.output, output);
    let bound = &run.best;
    assert_eq!(bound.len(), set.frames.len());
    let score = |i: usize, p| score_frame(&set.frames[i], W, H, p, &rules);
    for i in 0..set.frames.len() {
        let (o, b) = (score(i, &output[i]), score(i, &bound[i]));
        assert_eq!(o.label_lanes, b.label_lanes, "frame {i}");
        assert!(
            b.tusimple_acc_sum >= o.tusimple_acc_sum,
            "frame {i}: {b:?} below {o:?}"
        );
    }
    // Both output lanes on their labels: the output itself.
    assert_eq!(bound[0], output[0]);
    // The right label on the neighbour's mark, which the choice passed over: the bound takes
    // that candidate (matched), the left lane stays the output's.
    let (o, b) = (score(2, &output[2]), score(2, &bound[2]));
    assert_eq!((o.tusimple_matched, b.tusimple_matched), (1, 2));
    assert_eq!(bound[2][0], output[2][0]);
    // The right label 40 px from any mark: no candidate comes near it, the output stays.
    assert_eq!(bound[1], output[1]);
    // Best or none: the far right lane of frame 1 (no label point within the tolerance) is not
    // reported; where the best lane matches, it is the best.
    assert!(bound[1][1].is_some());
    assert_eq!(run.best_or_none[1], [bound[1][0], None]);
    for i in [0, 2] {
        assert_eq!(run.best_or_none[i], bound[i], "frame {i}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
