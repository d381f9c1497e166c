//! Consistency statistics: NEES, χ² quantiles and the Monte Carlo acceptance band.
//!
//! For a consistent filter, NEES = eᵀP⁻¹e ~ χ²(n) and NIS = νᵀS⁻¹ν ~ χ²(m). Averaged over `runs`
//! independent Monte Carlo runs, runs·(average) ~ χ²(runs·dof), so the two-sided band for the
//! average at confidence 1−α is [χ²_{α/2}(runs·dof), χ²_{1−α/2}(runs·dof)] / runs.

use nalgebra::{SMatrix, SVector};
use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

use crate::AkfError;
use crate::linalg::{check_finite, cholesky_lower, mahalanobis_squared};

/// Normalised estimation error squared eᵀP⁻¹e (dimensionless), e = x_true − x̂.
///
/// `covariance` must be PD (its lower triangle is factorised; a failure names the pivot).
pub fn nees<const N: usize>(
    error: &SVector<f64, N>,
    covariance: &SMatrix<f64, N, N>,
) -> Result<f64, AkfError> {
    check_finite("error", error)?;
    check_finite("covariance", covariance)?;
    let l = cholesky_lower("covariance", covariance)?;
    Ok(mahalanobis_squared(&l, error))
}

fn check_probability(p: f64) -> Result<(), AkfError> {
    if p > 0.0 && p < 1.0 {
        Ok(())
    } else {
        Err(AkfError::InvalidParameter {
            field: "p",
            reason: format!("{p} is outside (0, 1)"),
        })
    }
}

/// Standard normal quantile Φ⁻¹(p), 0 < p < 1 (`statrs`: Φ⁻¹(p) = −√2·erfc⁻¹(2p), to round-off).
pub fn normal_quantile(p: f64) -> Result<f64, AkfError> {
    check_probability(p)?;
    let n = Normal::new(0.0, 1.0).map_err(|e| AkfError::InvalidParameter {
        field: "normal",
        reason: e.to_string(),
    })?;
    Ok(n.inverse_cdf(p))
}

/// χ² quantile with `dof` (> 0, not necessarily integer) degrees of freedom, the exact inverse of
/// the regularised lower incomplete gamma function (`statrs`), 0 < p < 1.
pub fn chi_square_quantile(p: f64, dof: f64) -> Result<f64, AkfError> {
    if !(dof.is_finite() && dof > 0.0) {
        return Err(AkfError::InvalidParameter {
            field: "dof",
            reason: format!("{dof} must be finite and > 0"),
        });
    }
    check_probability(p)?;
    let d = ChiSquared::new(dof).map_err(|e| AkfError::InvalidParameter {
        field: "dof",
        reason: e.to_string(),
    })?;
    Ok(d.inverse_cdf(p))
}

/// Two-sided acceptance band for the average of `runs` independent χ²(`dof`) statistics at
/// `confidence` (e.g. 0.95): returns (lower, upper) for the average.
pub fn average_band(dof: usize, runs: usize, confidence: f64) -> Result<(f64, f64), AkfError> {
    if dof == 0 {
        return Err(AkfError::InvalidParameter {
            field: "dof",
            reason: "must be ≥ 1".into(),
        });
    }
    if runs == 0 {
        return Err(AkfError::InvalidParameter {
            field: "runs",
            reason: "must be ≥ 1".into(),
        });
    }
    if !(confidence > 0.0 && confidence < 1.0) {
        return Err(AkfError::InvalidParameter {
            field: "confidence",
            reason: format!("{confidence} is outside (0, 1)"),
        });
    }
    let k = (dof * runs) as f64;
    let alpha = 1.0 - confidence;
    let lo = chi_square_quantile(0.5 * alpha, k)? / runs as f64;
    let hi = chi_square_quantile(1.0 - 0.5 * alpha, k)? / runs as f64;
    Ok((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_quantile_matches_tabulated_values() {
        // Reference values: standard tables (Abramowitz & Stegun 26.2).
        assert!((normal_quantile(0.975).unwrap() - 1.959_963_984_540_054).abs() < 1e-8);
        assert!((normal_quantile(0.01).unwrap() + 2.326_347_874_040_841).abs() < 1e-8);
        assert!((normal_quantile(0.999).unwrap() - 3.090_232_306_167_813).abs() < 1e-8);
        assert!(normal_quantile(0.5).unwrap().abs() < 1e-15);
        assert!(normal_quantile(0.0).is_err());
        assert!(normal_quantile(1.0).is_err());
    }

    #[test]
    fn chi_square_quantile_matches_tables() {
        // Tabulated χ² quantiles (NIST/SEMATECH e-Handbook, table 1.3.6.7.4, 3 decimals).
        let cases = [
            (0.95, 10.0, 18.307),
            (0.05, 10.0, 3.940),
            (0.975, 100.0, 129.561),
            (0.95, 2.0, 5.991),
            (0.99, 1.0, 6.635),
        ];
        for (p, k, expected) in cases {
            let q = chi_square_quantile(p, k).unwrap();
            assert!(
                (q - expected).abs() < 6e-4,
                "p={p} k={k}: {q} vs {expected}"
            );
        }
        // χ²(2) has the closed form F(x) = 1 − e^{−x/2}: the quantile is −2 ln(1 − p).
        for p in [0.001, 0.1, 0.5, 0.9, 0.999] {
            let q = chi_square_quantile(p, 2.0).unwrap();
            let exact = -2.0 * (1.0 - p).ln();
            assert!(
                (q - exact).abs() < 1e-9 * exact.max(1.0),
                "p={p}: {q} vs {exact}"
            );
        }
        assert!(chi_square_quantile(0.5, 0.0).is_err());
        assert!(chi_square_quantile(1.0, 3.0).is_err());
    }

    #[test]
    fn average_bands_match_the_project_consistency_table() {
        // /work/shared/docs/ins-sd.md § Consistency (two-sided 95 %).
        let table = [
            (15, 50, 13.52, 16.56),
            (15, 100, 13.95, 16.09),
            (6, 50, 5.08, 7.00),
            (6, 100, 5.34, 6.70),
        ];
        for (dof, runs, lo, hi) in table {
            let (a, b) = average_band(dof, runs, 0.95).unwrap();
            assert!(
                (a - lo).abs() < 0.006 && (b - hi).abs() < 0.006,
                "{dof},{runs}: {a},{b}"
            );
        }
    }

    #[test]
    fn nees_equals_explicit_inverse_form() {
        let p = SMatrix::<f64, 2, 2>::new(4.0, 1.0, 1.0, 2.0);
        let e = SVector::<f64, 2>::new(1.0, -1.0);
        let reference = e.dot(&(p.try_inverse().unwrap() * e));
        assert!((nees(&e, &p).unwrap() - reference).abs() < 1e-14);
        let bad = SMatrix::<f64, 2, 2>::new(1.0, 2.0, 2.0, 1.0);
        assert!(matches!(
            nees(&e, &bad),
            Err(AkfError::NotPositiveDefinite { pivot: 1, .. })
        ));
    }
}
