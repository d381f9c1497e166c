use super::*;

const W: usize = 96;
const H: usize = 64;

/// A seeded standard normal sequence (xorshift64* and Box–Muller), independent of any crate.
struct Normal(u64);

impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn next(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// A grey ramp (left to right, 60 → 155) with a bright vertical mark 4 px wide at column 48,
/// plus seeded Gaussian noise of `sigma_grey`.
fn scene(sigma_grey: f64, seed: u64) -> Vec<u8> {
    let mut noise = Normal(seed);
    let mut px = vec![0u8; W * H];
    for y in 0..H {
        for x in 0..W {
            let mark = if (48..52).contains(&x) { 80.0 } else { 0.0 };
            let v = 60.0 + x as f64 + mark + sigma_grey * noise.next();
            px[y * W + x] = v.round().clamp(0.0, 255.0) as u8;
        }
    }
    px
}

fn image(px: &[u8]) -> GreyImage<'_> {
    GreyImage::new(px, W, H, W).expect("test image")
}

/// The standard deviation of `a − b` over the pixels at least 3 columns from the mark and the
/// borders (rows `[2, H − 2)`).
fn residual_sigma(a: &[u8], b: &[u8]) -> f64 {
    let mut d = Vec::new();
    for y in 2..H - 2 {
        for x in (2..W - 2).filter(|x| !(45..55).contains(x)) {
            d.push(f64::from(a[y * W + x]) - f64::from(b[y * W + x]));
        }
    }
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    (d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / d.len() as f64).sqrt()
}

#[test]
fn the_noise_estimate_reads_the_added_noise_and_ignores_ramps_and_marks() {
    let mut hist = [0u32; 256];
    for (sigma, lo, hi) in [(0.0, 0.0, 0.3), (4.0, 3.4, 4.6), (8.0, 7.2, 8.8)] {
        let px = scene(sigma, 7);
        let n = noise_sigma_grey(&image(&px), (0, H), &mut hist).expect("rows to read");
        assert!((lo..=hi).contains(&n), "σ {sigma}: σ̂ {n}");
    }
    // A band without a row above and below each read row: nothing to read.
    assert_eq!(
        noise_sigma_grey(&image(&scene(8.0, 7)), (0, 1), &mut hist),
        None
    );
}

#[test]
fn the_smoothing_is_the_direct_two_dimensional_mask_with_clamped_borders() {
    let px = scene(8.0, 11);
    let mut sums = vec![0u16; W * H];
    let mut out = vec![0u8; W * H];
    smooth_binomial(&image(&px), (0, H), &mut sums, &mut out).expect("buffers sized");
    let k = [1.0, 2.0, 1.0];
    for y in 0..H {
        for x in 0..W {
            let mut acc = 0.0;
            for (dy, ky) in k.iter().enumerate() {
                for (dx, kx) in k.iter().enumerate() {
                    let yy = (y + dy).saturating_sub(1).min(H - 1);
                    let xx = (x + dx).saturating_sub(1).min(W - 1);
                    acc += ky * kx * f64::from(px[yy * W + xx]);
                }
            }
            // The mask's mean, rounded half up.
            let expected = (acc / 16.0 + 0.5).floor() as u8;
            assert_eq!(out[y * W + x], expected, "({x}, {y}): {acc}");
        }
    }
}

#[test]
fn smoothing_writes_only_the_rows_asked_for_and_refuses_short_buffers() {
    let px = scene(8.0, 13);
    let mut sums = vec![0u16; W * H];
    let mut out = vec![9u8; W * H];
    smooth_binomial(&image(&px), (10, 20), &mut sums, &mut out).expect("buffers sized");
    assert!(out[..10 * W].iter().chain(&out[20 * W..]).all(|&v| v == 9));
    let mut short = vec![9u8; 20 * W - 1];
    assert_eq!(
        smooth_binomial(&image(&px), (10, 20), &mut sums, &mut short),
        Err(GradientError::BufferTooSmall {
            buffer: "out",
            len: 20 * W - 1,
            required: 20 * W
        })
    );
    assert!(short.iter().all(|&v| v == 9));
}

#[test]
fn smoothing_keeps_three_eighths_of_the_noise_and_three_quarters_of_a_step() {
    let (clean, noisy) = (scene(0.0, 5), scene(8.0, 5));
    let smooth = |px: &[u8]| {
        let (mut sums, mut out) = (vec![0u16; W * H], vec![0u8; W * H]);
        smooth_binomial(&image(px), (0, H), &mut sums, &mut out).expect("buffers sized");
        out
    };
    let (smoothed, smoothed_clean) = (smooth(&noisy), smooth(&clean));
    let before = residual_sigma(&noisy, &clean);
    let after = residual_sigma(&smoothed, &smoothed_clean);
    // σ × 0.375 by the binomial (rounding adds a little).
    assert!(
        after < 0.45 * before && after > 0.3 * before,
        "{before} → {after}"
    );
    // The mark's left step (columns 47 → 48, 80 levels): the largest central difference across
    // it, what a Sobel reads, 3/4 of the clean frame's after smoothing (within rounding).
    let y = H / 2;
    let step = |f: &[u8]| {
        (44..52)
            .map(|x| f64::from(f[y * W + x + 1]) - f64::from(f[y * W + x - 1]))
            .fold(f64::MIN, f64::max)
    };
    let (raw, kept) = (step(&clean), step(&smoothed_clean));
    assert!((kept - 0.75 * raw).abs() < 0.05 * raw, "{raw} → {kept}");
}
