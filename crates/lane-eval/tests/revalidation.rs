//! The period's re-validation spread over its frames (`track.revalidate_spread`, module
//! `lane_tracker::tracker::revalidation`) on the real udacity clip (read from the data root,
//! `lane_bench::data`; missing, it fails under CI and skips, saying so, elsewhere).
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_eval::eval::{TrackRun, continuity, run_tracker};
use lane_io::y4m::Y4mSource;
use lane_tracker::{Estimator, TrackerConfig};

/// The real udacity clip; `None` (skipped, said on stderr) when it is missing outside CI, a
/// failure naming it under CI.
fn udacity_clip() -> Option<std::path::PathBuf> {
    lane_bench::data::test_data_file(lane_bench::data::UDACITY_CLIP)
        .unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_real_udacity_clip_keeps_both_lanes_with_the_spread_revalidation_as_without() {
    // The default spreads the period's re-validation over its frames (`track.revalidate_spread`,
    // module `lane_tracker::tracker::revalidation`): on this clip every period's choice keeps the
    // pair, so no frame after the first re-validates whole, and every frame's lanes are those of
    // the whole re-validation on every 10th frame.
    let Some(path) = udacity_clip() else {
        return;
    };
    let run = |spread: bool| {
        let file = std::io::BufReader::new(std::fs::File::open(&path).unwrap());
        let mut source = Y4mSource::new(file, path.display().to_string()).unwrap();
        let mut cfg = TrackerConfig::default_preset().unwrap();
        cfg.track.revalidate_spread = spread;
        run_tracker(&mut source, &cfg, Estimator::Kif, None).unwrap()
    };
    let (spread, whole) = (run(true), run(false));
    let c = continuity(&spread.reports, 239.0);
    assert_eq!(c.frames, 221, "{c:?}");
    assert_eq!(c.frames_both_reported, 221, "{c:?}");
    // Frame 0 initialises; the periods end on frames 10, 20, …, 220.
    for r in [&spread, &whole] {
        assert_eq!(r.counters.revalidations, 22, "{:?}", r.counters);
        assert_eq!(r.counters.revalidation_switches, [0, 0], "{:?}", r.counters);
        assert_eq!(r.counters.initialisations, [1, 1], "{:?}", r.counters);
    }
    let whole_frames = |r: &TrackRun| -> Vec<usize> {
        (r.reports.iter().enumerate())
            .filter(|(_, t)| t.unwrap().full_gradient)
            .map(|(i, _)| i)
            .collect()
    };
    assert_eq!(whole_frames(&spread), [0]);
    assert_eq!(
        whole_frames(&whole),
        (0..=220).step_by(10).collect::<Vec<_>>()
    );
    for (i, (a, b)) in spread.reports.iter().zip(&whole.reports).enumerate() {
        let (a, b) = (a.unwrap(), b.unwrap());
        assert_eq!((a.lanes, a.road), (b.lanes, b.road), "frame {i}");
    }
}
