use super::super::denoise::Denoiser;
use super::*;

const W: usize = 48;
const H: usize = 32;

/// A flat frame of one grey with a bright mark (columns 20..24) of `mark` grey: its median is
/// `grey`.
fn frame(grey: u8, mark: u8) -> Vec<u8> {
    (0..W * H)
        .map(|i| {
            if (20..24).contains(&(i % W)) {
                mark
            } else {
                grey
            }
        })
        .collect()
}

fn image(px: &[u8]) -> GreyImage<'_> {
    GreyImage::new(px, W, H, W).expect("test image")
}

#[test]
fn a_frame_darker_than_the_limit_is_brightened_up_to_it_and_one_at_it_is_not() {
    let mut stage = Exposure::new(50.0);
    let dark = frame(25, 60);
    stage.measure_frame(&image(&dark), (0, H));
    assert_eq!(
        stage.last(),
        FrameExposure {
            median_grey: 25.0,
            gain: 2.0
        }
    );
    // A third of the limit: capped at MAX_EXPOSURE_GAIN.
    stage.measure_frame(&image(&frame(10, 40)), (0, H));
    assert_eq!(stage.last().gain, MAX_EXPOSURE_GAIN);
    stage.measure_frame(&image(&frame(40, 90)), (0, H));
    assert!((stage.last().gain - 1.25).abs() < 1e-12);
    stage.measure_frame(&image(&frame(50, 90)), (0, H));
    assert_eq!(stage.last().gain, 1.0);
    // Off: never measured.
    let mut off = Exposure::new(0.0);
    off.measure_frame(&image(&dark), (0, H));
    assert_eq!(off.last(), FrameExposure::NONE);
}

#[test]
fn every_frame_is_measured_and_a_reset_forgets_the_last() {
    // A bright frame after a dark one is read as it is (a gain carried would saturate it).
    let mut stage = Exposure::new(50.0);
    stage.measure_frame(&image(&frame(25, 60)), (0, H));
    assert_eq!(stage.last().gain, 2.0);
    stage.measure_frame(&image(&frame(120, 200)), (0, H));
    assert_eq!(
        stage.last(),
        FrameExposure {
            median_grey: 120.0,
            gain: 1.0
        }
    );
    stage.reset();
    assert_eq!(stage.last(), FrameExposure::NONE);
}

#[test]
fn the_frame_as_read_is_brightened_by_the_gain_and_its_noise_judged_brightened() {
    let dark = frame(25, 60);
    // Noise off, brightening on: the buffer is kept and the frame brightened.
    let mut levels = Denoiser::new(0.0, true, W, H);
    levels.measure_if_due(&image(&dark), (0, H), true, 2.0);
    let read = levels
        .frame_as_read(&image(&dark), (0, H))
        .expect("a brightened frame is written");
    assert_eq!(read, frame(50, 120));
    levels.put_back(read);
    // Gain 1: read as it is.
    levels.measure_if_due(&image(&dark), (0, H), true, 1.0);
    assert!(levels.frame_as_read(&image(&dark), (0, H)).is_none());
    // A checkerboard of ±1 (σ̂ ≈ 3.95) passes the limit of 4 as it is, not brightened twice.
    let board: Vec<u8> = (0..W * H)
        .map(|i| {
            if (i % W + i / W).is_multiple_of(2) {
                31
            } else {
                29
            }
        })
        .collect();
    let mut noise = Denoiser::new(4.0, true, W, H);
    noise.measure_if_due(&image(&board), (0, H), true, 1.0);
    assert!(!noise.last().denoised);
    noise.measure_if_due(&image(&board), (0, H), true, 2.0);
    assert!(noise.last().denoised, "σ̂ · gain = 7.9 > 4");
    let read = noise
        .frame_as_read(&image(&board), (0, H))
        .expect("smoothed and brightened");
    // Smoothed to 30 ± 1, then doubled.
    assert!(read[W + 1..2 * W - 1].iter().all(|&v| v.abs_diff(60) <= 2));
}

#[test]
fn the_noise_carried_between_measurements_is_judged_with_each_frames_gain() {
    // σ̂ ≈ 3.95 measured on a scene's first frame; the next frames are not measured again, but a
    // frame brightened twofold is smoothed (7.9 > 4) and one read as it is is not.
    let board: Vec<u8> = (0..W * H)
        .map(|i| {
            if (i % W + i / W).is_multiple_of(2) {
                31
            } else {
                29
            }
        })
        .collect();
    let flat = frame(30, 30);
    let mut noise = Denoiser::new(4.0, true, W, H);
    noise.measure_if_due(&image(&board), (0, H), true, 1.0);
    assert!(!noise.last().denoised);
    noise.measure_if_due(&image(&flat), (0, H), false, 2.0);
    assert!((noise.last().sigma_grey - 3.95).abs() < 0.01, "carried");
    assert!(noise.last().denoised);
    noise.measure_if_due(&image(&flat), (0, H), false, 1.0);
    assert!(!noise.last().denoised);
}
