//! Sage–Husa against its independent forms (running average at b = 1, explicit exponentially
//! weighted mean), and the structured NNLS projection against brute-force enumeration of the
//! active sets.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use akf::{QProjection, SageHusaConfig, SageHusaQ, nnls_gram, project_structured};
use nalgebra::{DMatrix, DVector, SMatrix, SVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

type M3 = SMatrix<f64, 3, 3>;

fn random_push_data(rng: &mut ChaCha8Rng, n: usize) -> Vec<(SVector<f64, 3>, M3, M3, M3)> {
    (0..n)
        .map(|_| {
            let dx = SVector::<f64, 3>::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let a = M3::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let b = M3::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let phi = M3::identity() + M3::from_fn(|_, _| rng.random_range(-0.1..0.1));
            (dx, a * a.transpose(), b * b.transpose(), phi)
        })
        .collect()
}

fn single(d: &(SVector<f64, 3>, M3, M3, M3)) -> M3 {
    let (dx, p, pp, phi) = d;
    let q = dx * dx.transpose() + p - phi * pp * phi.transpose();
    (q + q.transpose()) * 0.5
}

fn config(b: f64) -> SageHusaConfig {
    SageHusaConfig {
        forgetting: b,
        warmup: 1,
        projection: QProjection::Diagonal,
        min_variance: 0.0,
    }
}

#[test]
fn sage_husa_with_b_one_is_the_running_average_and_b_to_one_tends_to_it() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let data = random_push_data(&mut rng, 40);
    let mut one = SageHusaQ::<3>::new(config(1.0)).unwrap();
    let mut near = SageHusaQ::<3>::new(config(1.0 - 1e-9)).unwrap();
    let mut sum = M3::zeros();
    for (k, d) in data.iter().enumerate() {
        one.push(&d.0, &d.1, &d.2, &d.3).unwrap();
        near.push(&d.0, &d.1, &d.2, &d.3).unwrap();
        sum += single(d);
        let mean = sum / (k + 1) as f64;
        let e1 = (one.raw_estimate().unwrap() - mean).amax();
        let e2 = (near.raw_estimate().unwrap() - mean).amax();
        assert!(e1 <= 1e-12 * mean.amax().max(1.0), "k {k}: {e1}");
        assert!(e2 <= 1e-6 * mean.amax().max(1.0), "k {k}: {e2}");
    }
}

#[test]
fn sage_husa_is_the_exponentially_weighted_mean() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let data = random_push_data(&mut rng, 30);
    for b in [0.5, 0.9, 0.98] {
        let mut est = SageHusaQ::<3>::new(config(b)).unwrap();
        for (k, d) in data.iter().enumerate() {
            est.push(&d.0, &d.1, &d.2, &d.3).unwrap();
            // Independent form: Σ b^{k−j} q_j / Σ b^{k−j}.
            let (mut num, mut den) = (M3::zeros(), 0.0);
            for (j, dj) in data[..=k].iter().enumerate() {
                let w = b.powi((k - j) as i32);
                num += single(dj) * w;
                den += w;
            }
            let want = num / den;
            let e = (est.raw_estimate().unwrap() - want).amax();
            assert!(e <= 1e-12 * want.amax().max(1.0), "b {b}, k {k}: {e}");
        }
    }
    // The warm-up withholds the estimate; the projection is PSD (diagonal ≥ 0).
    let mut est = SageHusaQ::<3>::new(SageHusaConfig {
        warmup: 5,
        ..config(0.9)
    })
    .unwrap();
    for (k, d) in data.iter().take(6).enumerate() {
        let got = est.push(&d.0, &d.1, &d.2, &d.3).unwrap().is_some();
        assert_eq!(got, k + 1 >= 5);
    }
    let q = est.estimate().unwrap();
    assert!((0..3).all(|i| q[(i, i)] >= 0.0));
    assert!(SageHusaQ::<3>::new(config(0.0)).is_err());
    assert!(SageHusaQ::<3>::new(config(1.5)).is_err());
}

/// Brute force: every subset S of the variables, unconstrained least squares on S, keep the
/// feasible (all ≥ 0) solution of least objective ½ qᵀGq − rᵀq.
fn brute_force<const K: usize>(g: &SMatrix<f64, K, K>, r: &SVector<f64, K>) -> SVector<f64, K> {
    let mut best = (0.0, SVector::<f64, K>::zeros()); // q = 0 is always feasible, objective 0
    for mask in 1u32..(1 << K) {
        let idx: Vec<usize> = (0..K).filter(|i| mask & (1 << i) != 0).collect();
        let gs = DMatrix::from_fn(idx.len(), idx.len(), |a, b| g[(idx[a], idx[b])]);
        let rs = DVector::from_fn(idx.len(), |a, _| r[idx[a]]);
        let Some(z) = gs.lu().solve(&rs) else {
            continue;
        };
        if z.iter().any(|v| *v < -1e-12) {
            continue;
        }
        let mut q = SVector::<f64, K>::zeros();
        for (a, &i) in idx.iter().enumerate() {
            q[i] = z[a].max(0.0);
        }
        let f = 0.5 * (q.transpose() * g * q)[(0, 0)] - r.dot(&q);
        if f < best.0 {
            best = (f, q);
        }
    }
    best.1
}

#[test]
fn nnls_equals_brute_force_on_small_problems() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut active_cases = 0;
    for case in 0..300 {
        let a = SMatrix::<f64, 6, 4>::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let y = SVector::<f64, 6>::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let g = a.transpose() * a;
        let r = a.transpose() * y;
        let q = nnls_gram(&g, &r);
        let bf = brute_force(&g, &r);
        assert!(q.iter().all(|v| *v >= 0.0), "case {case}: {q}");
        assert!(
            (q - bf).amax() <= 1e-9 * (1.0 + bf.amax()),
            "case {case}: {q} vs {bf}"
        );
        if bf.iter().any(|v| *v == 0.0) && bf.iter().any(|v| *v > 0.0) {
            active_cases += 1;
        }
    }
    // The constraint was active (some, not all, densities at 0) in many cases.
    assert!(active_cases > 50, "{active_cases}");
}

#[test]
fn structured_projection_recovers_a_member_and_projects_a_non_member() {
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let mk = |rng: &mut ChaCha8Rng| {
        let g = SVector::<f64, 4>::from_fn(|_, _| rng.random_range(-1.0..1.0));
        g * g.transpose()
    };
    let basis = [mk(&mut rng), mk(&mut rng), mk(&mut rng)];
    let scale = SVector::<f64, 4>::new(1.0, 4.0, 0.25, 9.0);
    // A member of the cone comes back exactly.
    let q_true = SVector::<f64, 3>::new(0.5, 0.0, 2.0);
    let member: SMatrix<f64, 4, 4> = basis[0] * 0.5 + basis[2] * 2.0;
    let fit = project_structured(&member, &basis, &scale).unwrap();
    assert!((fit.densities - q_true).amax() < 1e-9, "{}", fit.densities);
    assert!((fit.matrix - member).amax() < 1e-9);
    // A raw estimate with a negative density: the fit is the brute-force NNLS of the scaled
    // Frobenius problem, and PSD.
    let raw: SMatrix<f64, 4, 4> = basis[0] * 0.5 - basis[1] * 1.5 + basis[2] * 0.2;
    let fit = project_structured(&raw, &basis, &scale).unwrap();
    let w = |m: &SMatrix<f64, 4, 4>| {
        SVector::<f64, 16>::from_fn(|k, _| {
            let (i, j) = (k / 4, k % 4);
            m[(i, j)] / (scale[i] * scale[j]).sqrt()
        })
    };
    let a = SMatrix::<f64, 16, 3>::from_columns(&[w(&basis[0]), w(&basis[1]), w(&basis[2])]);
    let bf = brute_force(&(a.transpose() * a), &(a.transpose() * w(&raw)));
    assert!(
        (fit.densities - bf).amax() < 1e-9,
        "{} vs {bf}",
        fit.densities
    );
    assert!(fit.densities[1] == 0.0);
    assert!(fit.matrix.symmetric_eigenvalues().min() >= -1e-12);
    // Basis matrices of very different magnitudes (like white noise on ψ and on δv per unit
    // density): a member is still recovered exactly (the fit works in normalised variables).
    let wide = [basis[0] * 1e12, basis[1], basis[2] * 1e-9];
    let member: SMatrix<f64, 4, 4> = wide[0] * 3e-12 + wide[2] * 5e8;
    let fit = project_structured(&member, &wide, &scale).unwrap();
    let want = SVector::<f64, 3>::new(3e-12, 0.0, 5e8);
    for k in 0..3 {
        assert!(
            (fit.densities[k] - want[k]).abs() <= 1e-9 * want[k].abs().max(1e-30),
            "{k}: {} vs {}",
            fit.densities[k],
            want[k]
        );
    }
}
