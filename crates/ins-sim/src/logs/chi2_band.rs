//! The band a time-averaged NEES is judged against when its epochs are correlated.
//!
//! A consistent filter's NEES at one compared time, ε_k = e_kᵀ P_k⁻¹ e_k, is χ²(d): mean d,
//! variance 2d. Averaged over N times and divided by d, ε̄ = (1/(N d)) Σ_k ε_k has mean 1
//! whatever the correlation between times, but its variance is
//!
//! ```text
//! Var ε̄ = (2 / (N d)) · τ,    τ = 1 + 2 Σ_{l=1}^{N−1} (1 − l/N) ρ(l)
//! ```
//!
//! with ρ(l) the autocorrelation of ε_k at lag l. Independent times have τ = 1, and N d ε̄ is
//! χ²(N d): the band a replay printed before issue 54. A navigation filter's consecutive errors
//! are strongly correlated — between updates the error drifts smoothly, and the reference is
//! compared at 4–200 Hz — so τ is tens to thousands of compared times, and that band was far
//! too narrow (0.973–1.027 per dof: a healthy 0.69 looked far out of it).
//!
//! [`nees_band`] accounts for the correlation: N_eff = N / τ is the number of independent times
//! whose mean has the same variance, and the band is that of χ²(ν)/ν with ν = N_eff · d, which
//! matches the mean and the variance of ε̄ (Satterthwaite's approximation; exact for
//! independent times, N_eff = N). τ is estimated from the series itself
//! ([`autocorrelation_time`]): the sample autocorrelation
//!
//! ```text
//! ρ̂(l) = γ̂(l) / γ̂(0),    γ̂(l) = (1/N) Σ_{k=0}^{N−1−l} (ε_k − ε̄)(ε_{k+l} − ε̄)
//! ```
//!
//! (the 1/N normalisation carries the (1 − l/N) weights) summed by Geyer's initial positive
//! sequence: for a stationary series Γ_m = ρ̂(2m) + ρ̂(2m+1) is positive, so the sum stops at
//! the first m with Γ_m ≤ 0, beyond which ρ̂ is noise, and τ̂ = 2 Σ_m Γ_m − 1. N_eff is
//! clamped to [1, N].
//!
//! Assumptions, stated where the band is printed: the NEES series is stationary over the
//! replay (a filter still converging from its initial σ is not, and its early times weigh
//! more), and the replay spans several τ (with few effective times the band is wide, as it
//! should be). The NIS band is left as it was: a consistent filter's innovations are white, so
//! its epochs are independent under the hypothesis the band tests.

/// Two-sided confidence of the bands.
pub const BAND_CONFIDENCE: f64 = 0.95;

/// Longest series whose autocorrelation is summed directly; a longer one is first averaged in
/// blocks (see [`autocorrelation_time`]), which bounds the work at about this number squared.
pub const DIRECT_MAX_SAMPLES: usize = 8192;

/// Integrated autocorrelation time τ̂ of `x`, in samples (module docs: Geyer's initial positive
/// sequence); 1 for fewer than 2 samples or a constant series.
///
/// A series longer than [`DIRECT_MAX_SAMPLES`] is first averaged in blocks of k consecutive
/// samples (k = ⌈N / DIRECT_MAX_SAMPLES⌉, the last partial block left out): the mean of the
/// block means is the series' mean, so with their variance s_y² and autocorrelation time τ_y,
/// Var ε̄ = s_y² τ_y / (N/k) = s_x² τ_x / N gives τ_x = k τ_y s_y² / s_x² — valid whether τ is
/// shorter or longer than a block.
pub fn autocorrelation_time(x: &[f64]) -> f64 {
    let n = x.len();
    if n <= DIRECT_MAX_SAMPLES {
        return geyer_time(x);
    }
    let k = n.div_ceil(DIRECT_MAX_SAMPLES);
    let y: Vec<f64> = x
        .chunks_exact(k)
        .map(|c| c.iter().sum::<f64>() / k as f64)
        .collect();
    let used = &x[..y.len() * k];
    let (var_x, var_y) = (variance(used), variance(&y));
    if !(var_x > 0.0 && var_x.is_finite()) {
        return 1.0;
    }
    (k as f64 * geyer_time(&y) * var_y / var_x).max(f64::MIN_POSITIVE)
}

/// Population variance (1/N); 0 when empty.
fn variance(x: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    x.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n
}

/// τ̂ by Geyer's initial positive sequence over every lag of `x`.
fn geyer_time(x: &[f64]) -> f64 {
    let n = x.len();
    if n < 2 {
        return 1.0;
    }
    let mean = x.iter().sum::<f64>() / n as f64;
    let gamma = |lag: usize| -> f64 {
        x.iter()
            .zip(&x[lag..])
            .map(|(a, b)| (a - mean) * (b - mean))
            .sum::<f64>()
            / n as f64
    };
    let gamma0 = gamma(0);
    if !(gamma0 > 0.0 && gamma0.is_finite()) {
        return 1.0;
    }
    let mut sum = 0.0;
    let mut m = 0;
    while 2 * m + 1 < n {
        let pair = (gamma(2 * m) + gamma(2 * m + 1)) / gamma0;
        if pair <= 0.0 {
            break;
        }
        sum += pair;
        m += 1;
    }
    (2.0 * sum - 1.0).max(f64::MIN_POSITIVE)
}

/// The number of independent samples whose mean has the variance of `x`'s mean: N / τ̂,
/// clamped to [1, N] (N for fewer than 2 samples).
pub fn effective_samples(x: &[f64]) -> f64 {
    effective_of(x.len(), autocorrelation_time(x))
}

fn effective_of(n: usize, tau: f64) -> f64 {
    let n = n as f64;
    if n < 2.0 { n } else { (n / tau).clamp(1.0, n) }
}

/// The two-sided [`BAND_CONFIDENCE`] band of a mean χ² per degree of freedom over
/// `effective_samples` independent samples of `dof` degrees of freedom each: the quantiles of
/// χ²(ν)/ν, ν = `effective_samples` · `dof`. `None` for ν ≤ 0 or not finite.
pub fn mean_chi2_band(dof: f64, effective_samples: f64) -> Option<[f64; 2]> {
    let nu = dof * effective_samples;
    let alpha = 1.0 - BAND_CONFIDENCE;
    let lo = akf::chi_square_quantile(0.5 * alpha, nu).ok()? / nu;
    let hi = akf::chi_square_quantile(1.0 - 0.5 * alpha, nu).ok()? / nu;
    Some([lo, hi])
}

/// The band of a mean NEES per dof over a series of NEES.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeesBand {
    /// The [`BAND_CONFIDENCE`] band of the mean NEES per dof.
    pub band: [f64; 2],
    /// The effective number of independent times ([`effective_samples`]).
    pub effective_times: f64,
    /// The series' integrated autocorrelation time, in times ([`autocorrelation_time`]).
    pub autocorrelation_times: f64,
}

/// The band of a mean NEES per dof over the series `nees` (one NEES of `dof` degrees of freedom
/// per compared time), for its effective number of independent times; `None` when empty.
pub fn nees_band(nees: &[f64], dof: f64) -> Option<NeesBand> {
    if nees.is_empty() {
        return None;
    }
    let tau = autocorrelation_time(nees);
    let effective_times = effective_of(nees.len(), tau);
    Some(NeesBand {
        band: mean_chi2_band(dof, effective_times)?,
        effective_times,
        autocorrelation_times: tau,
    })
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    /// NEES of `n` times of a d-dimensional error that is an AR(1) process with coefficient `a`
    /// and unit marginal covariance (P = I): each NEES is χ²(d), consecutive ones correlated
    /// with ρ(l) = a^{2l}, so τ = (1 + a²)/(1 − a²).
    fn ar1_nees(rng: &mut ChaCha8Rng, n: usize, d: usize, a: f64, out: &mut Vec<f64>) {
        out.clear();
        let mut e: Vec<f64> = (0..d).map(|_| StandardNormal.sample(rng)).collect();
        let s = (1.0 - a * a).sqrt();
        for _ in 0..n {
            for v in &mut e {
                let w: f64 = StandardNormal.sample(rng);
                *v = a * *v + s * w;
            }
            out.push(e.iter().map(|v| v * v).sum());
        }
    }

    #[test]
    fn the_autocorrelation_time_of_white_and_ar1_series_is_their_theory() {
        let mut rng = ChaCha8Rng::seed_from_u64(54);
        let mut x = Vec::new();
        // Summed directly (8000 samples) and through block means (40 000 and 200 000).
        for (n, a, lo, hi) in [
            (8000, 0.0, 0.8, 1.2),
            (8000, 0.9, 6.5, 12.5),
            (40_000, 0.0, 0.85, 1.15),
            (40_000, 0.9, 7.5, 11.5),
            (40_000, 0.95, 15.0, 25.0),
            (200_000, 0.99, 80.0, 120.0),
        ] {
            ar1_nees(&mut rng, n, 6, a, &mut x);
            let tau = autocorrelation_time(&x);
            let theory = (1.0 + a * a) / (1.0 - a * a);
            assert!(
                (lo..hi).contains(&tau),
                "N = {n}, a = {a}: τ̂ {tau}, theory {theory}"
            );
        }
        assert_eq!(autocorrelation_time(&[]), 1.0);
        assert_eq!(autocorrelation_time(&[3.0; 10]), 1.0);
        assert_eq!(effective_samples(&[2.0]), 1.0);
        assert_eq!(effective_samples(&[4.0; 50]), 50.0);
    }

    /// Over many replays of a consistent filter with correlated errors, the mean NEES per dof
    /// falls inside the band for its effective times about 95 % of the time; inside the band
    /// for independent times far less often (the issue's trap).
    #[test]
    fn the_band_for_effective_times_covers_a_consistent_filter_with_correlated_errors() {
        let mut rng = ChaCha8Rng::seed_from_u64(2054);
        let (trials, n, d, a) = (400, 2000, 6, 0.95);
        let independent = mean_chi2_band(d as f64, n as f64).unwrap();
        let (mut inside, mut inside_independent) = (0, 0);
        let mut x = Vec::new();
        for _ in 0..trials {
            ar1_nees(&mut rng, n, d, a, &mut x);
            let mean = x.iter().sum::<f64>() / (n * d) as f64;
            let b = nees_band(&x, d as f64).unwrap();
            let ([lo, hi], n_eff) = (b.band, b.effective_times);
            assert!(n_eff < 0.2 * n as f64, "{n_eff}");
            inside += usize::from((lo..=hi).contains(&mean));
            inside_independent += usize::from((independent[0]..=independent[1]).contains(&mean));
        }
        let covered = inside as f64 / trials as f64;
        let covered_independent = inside_independent as f64 / trials as f64;
        // Binomial σ at 400 trials: 0.011.
        assert!((0.90..=0.99).contains(&covered), "{covered}");
        assert!(covered_independent < 0.55, "{covered_independent}");
        // Independent times: the band is the χ²(N d) one.
        let white = vec![6.0; 1];
        assert_eq!(
            nees_band(&white, 6.0).unwrap().band,
            mean_chi2_band(6.0, 1.0).unwrap()
        );
        assert_eq!(nees_band(&[], 6.0), None);
    }
}
