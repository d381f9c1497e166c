//! Consistency statistics: NEES, χ² quantiles and the Monte Carlo acceptance band.
//!
//! For a consistent filter, NEES = eᵀP⁻¹e ~ χ²(n) and NIS = νᵀS⁻¹ν ~ χ²(m). Averaged over `runs`
//! independent Monte Carlo runs, runs·(average) ~ χ²(runs·dof), so the two-sided band for the
//! average at confidence 1−α is [χ²_{α/2}(runs·dof), χ²_{1−α/2}(runs·dof)] / runs.

use nalgebra::{SMatrix, SVector};

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

/// Standard normal quantile Φ⁻¹(p), 0 < p < 1 (Acklam's rational approximation, relative
/// error < 1.2·10⁻⁹).
pub fn normal_quantile(p: f64) -> Result<f64, AkfError> {
    if !(p > 0.0 && p < 1.0) {
        return Err(AkfError::InvalidParameter {
            field: "p",
            reason: format!("{p} is outside (0, 1)"),
        });
    }
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    const P_LOW: f64 = 0.02425;
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    let x = if p < P_LOW {
        tail((-2.0 * p.ln()).sqrt())
    } else if p <= 1.0 - P_LOW {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    };
    Ok(x)
}

/// χ² quantile with `dof` degrees of freedom by the Wilson–Hilferty approximation
/// k·(1 − 2/(9k) + z_p·√(2/(9k)))³. Relative error ≈ 2·10⁻³ at k = 10, < 10⁻⁴ for k ≥ 100 (the
/// Monte Carlo bands use k = runs·dof, in the hundreds).
pub fn chi_square_quantile(p: f64, dof: f64) -> Result<f64, AkfError> {
    if !(dof.is_finite() && dof > 0.0) {
        return Err(AkfError::InvalidParameter {
            field: "dof",
            reason: format!("{dof} must be finite and > 0"),
        });
    }
    let z = normal_quantile(p)?;
    let c = 2.0 / (9.0 * dof);
    let base = (1.0 - c + z * c.sqrt()).max(0.0);
    Ok(dof * base * base * base)
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
        // Tabulated χ² quantiles (NIST/SEMATECH e-Handbook, table 1.3.6.7.4).
        let cases = [
            (0.95, 10.0, 18.307),
            (0.05, 10.0, 3.940),
            (0.975, 100.0, 129.561),
        ];
        for (p, k, expected) in cases {
            let q = chi_square_quantile(p, k).unwrap();
            assert!(
                (q - expected).abs() < 3e-3 * expected,
                "p={p} k={k}: {q} vs {expected}"
            );
        }
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
