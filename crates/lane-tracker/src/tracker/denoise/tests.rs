use super::*;

const W: usize = 48;
const H: usize = 32;

/// Grey 120 with a checkerboard of ±`amplitude`: `|I ∗ N| = 16·amplitude` at every pixel, so
/// σ̂ = 16·amplitude / (6 · 0.6745) ≈ 3.95·amplitude grey levels.
fn checkerboard(amplitude: u8) -> Vec<u8> {
    (0..W * H)
        .map(|i| {
            if (i % W + i / W).is_multiple_of(2) {
                120 + amplitude
            } else {
                120 - amplitude
            }
        })
        .collect()
}

fn image(px: &[u8]) -> GreyImage<'_> {
    GreyImage::new(px, W, H, W).expect("test image")
}

#[test]
fn a_frame_below_the_limit_is_read_as_it_is_and_one_above_is_smoothed() {
    // σ̂ 3.95 and 11.9 against the limit of 4.
    let (clean, noisy) = (checkerboard(1), checkerboard(3));
    let mut stage = Denoiser::new(4.0, false, W, H);
    stage.measure_if_due(&image(&clean), (0, H), true, 1.0);
    assert!((stage.last().sigma_grey - 3.95).abs() < 0.01);
    assert!(stage.frame_as_read(&image(&clean), (0, H)).is_none());
    // Not re-measured on a tracked frame before the period: still the clean frame's verdict.
    stage.measure_if_due(&image(&noisy), (0, H), false, 1.0);
    assert!(!stage.last().denoised);
    stage.measure_if_due(&image(&noisy), (0, H), true, 1.0);
    assert!(stage.last().denoised);
    let smoothed = stage
        .frame_as_read(&image(&noisy), (0, H))
        .expect("noisy frame smoothed");
    // The binomial averages a checkerboard away (inner pixels: (4·123 + … ) / 16 = 120 ± 0.75).
    assert!(
        smoothed[W + 1..2 * W - 1]
            .iter()
            .all(|&v| v.abs_diff(120) <= 1)
    );
    stage.put_back(smoothed);
    // Off: never measured.
    let mut off = Denoiser::new(0.0, false, W, H);
    off.measure_if_due(&image(&noisy), (0, H), true, 1.0);
    assert_eq!(off.last(), FrameNoise::NONE);
    assert!(off.frame_as_read(&image(&noisy), (0, H)).is_none());
}

#[test]
fn a_tracked_scene_is_measured_again_after_the_period() {
    let (clean, noisy) = (checkerboard(1), checkerboard(3));
    let mut stage = Denoiser::new(4.0, false, W, H);
    stage.measure_if_due(&image(&clean), (0, H), true, 1.0);
    for _ in 1..REMEASURE_EVERY_FRAMES {
        stage.measure_if_due(&image(&noisy), (0, H), false, 1.0);
        assert!(!stage.last().denoised);
    }
    stage.measure_if_due(&image(&noisy), (0, H), false, 1.0);
    assert!(stage.last().denoised, "measured on the period's frame");
    stage.reset();
    assert_eq!(stage.last(), FrameNoise::NONE);
}
