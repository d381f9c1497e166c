//! Dev check: render every synthetic scene, track it, print the scores.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]
use lane_eval::eval;
use lane_scenes as synth;
use lane_tracker::{Estimator, GreyFrame, LaneTracker};

fn main() {
    let est = if std::env::args().any(|a| a == "wrls") {
        Estimator::Wrls
    } else {
        Estimator::Kif
    };
    for spec in synth::SCENES {
        let mut r = synth::SceneRenderer::new(*spec, 320, 240);
        let truth = r.sequence_truth();
        let cfg = lane_io::config::load_tracker_config(spec.config).unwrap();
        let mut t = LaneTracker::new(&cfg, est, 320, 240).unwrap();
        let mut f = GreyFrame::default();
        let mut reps = Vec::new();
        for i in 0..spec.frames {
            r.render(i, &mut f);
            let rep = t.track(&f).unwrap();
            if std::env::var("V").is_ok() {
                eprintln!(
                    "{} {i}: {:?} {:?} {:?}/{:?} pts {} {}",
                    spec.name,
                    rep.lanes[0].state,
                    rep.lanes[1].state,
                    rep.lanes[0]
                        .col_at_row(200.0)
                        .map(|x| x - truth.frames[i as usize].lanes[0].col_at_row(200.0)),
                    rep.lanes[1]
                        .col_at_row(200.0)
                        .map(|x| x - truth.frames[i as usize].lanes[1].col_at_row(200.0)),
                    rep.lanes[0].points,
                    rep.lanes[1].points
                );
            }
            reps.push(Some(rep));
        }
        let s = eval::score_sequence(&truth, &reps);
        println!(
            "{:20} err {:.2} max {:.2} acc {:.3} miss {} false {} rec {} inits {}  {:?}",
            spec.name,
            s.mean_lateral_error_px,
            s.max_frame_lateral_error_px,
            s.accuracy,
            s.missed_lane_frames,
            s.false_lane_frames,
            s.max_recovery_frames,
            s.initialisations,
            t.counters()
        );
    }
}
