//! Property test of the tracker on arbitrary frames: any size from 3 × 3 (every one taken),
//! noise, bright stripes of any width and lean, blank rows — with the default configuration
//! (every addition beyond the paper, the stripe trace included; also with its widest stripe
//! and no gradient threshold, and with the narrowest stripe the trace takes and the highest
//! threshold) and the paper's (`outdoor`), KIF and WRLS, over a few frames — never panics, and
//! every reported lane has finite coefficients. (Seeded: `toml_config::mutate::config`.)
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use lane_tracker::{Estimator, GreyFrame, LaneTracker, TrackerConfig};
use proptest::prelude::*;
use toml_config::mutate::config;

/// A stripe: its column at the bottom row and at the top row (fractions of the width, may lie
/// outside), its width (px) and grey level.
type Stripe = (f64, f64, f64, u8);

/// A `w × h` frame: grey `floor` with `noise` levels of pseudo-random noise (from `seed`), the
/// stripes drawn over it, and the rows `[blank.0, blank.1)` (fractions of the height) set to 0.
fn frame(
    w: usize,
    h: usize,
    floor: u8,
    noise: u8,
    seed: u64,
    stripes: &[Stripe],
    blank: (f64, f64),
) -> GreyFrame {
    let mut state = seed | 1;
    let mut pixels = vec![0u8; w * h];
    for (i, p) in pixels.iter_mut().enumerate() {
        // xorshift64
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let (x, y) = ((i % w) as f64, (i / w) as f64);
        let t = if h > 1 { y / (h - 1) as f64 } else { 0.0 };
        let mut g =
            i32::from(floor) + (state % (u64::from(noise) + 1)) as i32 - i32::from(noise / 2);
        for &(bottom, top, width, grey) in stripes {
            let centre = (top + (bottom - top) * t) * w as f64;
            if (x - centre).abs() <= width / 2.0 {
                g = i32::from(grey);
            }
        }
        if (blank.0..blank.1).contains(&t) {
            g = 0;
        }
        *p = g.clamp(0, 255) as u8;
    }
    GreyFrame::from_vec(w, h, pixels).expect("a whole frame")
}

proptest! {
    #![proptest_config(config(96))]

    #[test]
    fn any_frame_is_tracked_without_a_panic_and_with_finite_lanes(
        w in prop_oneof![3usize..24, 24usize..200],
        h in prop_oneof![3usize..24, 24usize..150],
        floor in any::<u8>(),
        noise in prop_oneof![Just(0u8), any::<u8>()],
        seed in any::<u64>(),
        stripes in prop::collection::vec(
            (-0.5f64..1.5, -0.5f64..1.5, 0.0f64..40.0, any::<u8>()),
            0..6,
        ),
        blank in (0.0f64..1.0, 0.0f64..1.0),
        frames in 1usize..5,
    ) {
        let image = frame(w, h, floor, noise, seed, &stripes, blank);
        // The default at the ends of its stripe width and gradient threshold ranges too.
        let default = TrackerConfig::default_preset().expect("the default");
        let mut widest = default;
        widest.gradient.stripe_max_width_px = 200;
        widest.gradient.magnitude_threshold = 0;
        let mut narrowest = default;
        narrowest.init.kerb_foot = false;
        narrowest.gradient.stripe_max_width_px = 2;
        narrowest.gradient.magnitude_threshold = 2040;
        for cfg in [
            default,
            widest,
            narrowest,
            TrackerConfig::outdoor().expect("the outdoor preset"),
        ] {
            cfg.validate().expect("a valid configuration");
            for estimator in [Estimator::Kif, Estimator::Wrls] {
                // Every size from 3 × 3 is taken.
                let made = LaneTracker::new(&cfg, estimator, w, h);
                prop_assert!(made.is_ok(), "{w}×{h}: {:?}", made.err());
                let Ok(mut tracker) = made else { continue };
                for _ in 0..frames {
                    let report = tracker.track(&image).expect("a frame of the tracker's size");
                    for lane in report.lanes {
                        if let Some(c) = lane.coeffs {
                            prop_assert!(c.iter().all(|v| v.is_finite()), "{lane:?}");
                        }
                    }
                }
            }
        }
    }
}
