//! # ins-sim — the INS/SD closed loop of Lustosa, Chagas & Waldmann, §§5–6
//!
//! The simulation as a library: scenario file, one run ([`run`]), log export and replay
//! ([`logs`]), the one Monte Carlo run loop ([`runs`]) and the mergeable statistics ([`stats`]).
//! No thread pool and no figures (those are crate `ins-monte-carlo`'s), so the Python package
//! uses it as it is.
//!
//! Monte Carlo simulation of a strapdown INS aided by a sighting device (SD), in three modes
//! ([`Mode`]): stand-alone INS, INS/SD with a manually tuned Kalman filter, and INS/SD with
//! the adaptive KF of Mohamed & Schwarz (paper eq. 19). Built on the sibling crates:
//! `ins-errors` (truth trajectory, IMU errors, NED strapdown, 15-state ψ-angle error model),
//! `sighting-model` (nonlinear (w, h) offsets and their Jacobian H) and `akf` (Joseph-form KF,
//! adaptive Q̂). The filter itself is the online [`ins_sd_filter::InsSdFilter`]: this module
//! only simulates (truth, IMU errors, sightings) and feeds it time-stamped IMU samples and
//! sightings, exactly as `nav-app ins` feeds it logs — one filter code path. Moving the loop
//! onto that object left every record bit-identical (`cargo xtask monte-carlo --runs 20`: the
//! three `timeseries_*.csv` are byte-equal before and after).
//!
//! ## One run
//!
//! ```text
//! truth (100 Hz) ──► IMU: f̃ = f + ∇ + w_a, ω̃ = ω + ε + w_g ──► strapdown INS ──┐
//!        │                                                                      │ A(t) averaged
//!        │                            every T_SD = 1 s:                         ▼ on sub-intervals
//!        └──► z = h(truth, INS, landmarks) + v ──► KF/AKF: predict (Φ_T, Q_T), update (H at INS)
//!                                                       │ t ≥ 195 s: feedback
//!                                                       ▼
//!              INS ← INS − (δp̂, δv̂, ψ̂);  sensor corrections += (∇̂, ε̂);  x̂ ← 0, P kept
//! ```
//!
//! * Error state (15, `ins-errors` contract): x = (δp m NED, δv m/s NED, ψ rad, ∇ m/s² body,
//!   ε rad/s body), δ = computed − true.
//! * Continuous model (paper eqs. 10–14, as implemented and verified in `ins-errors`):
//!   δṗ = −ρ×δp + δv, δv̇ = G_p δp − (2Ω+ρ)×δv + f_n×ψ + C̃∇, ψ̇ = −(Ω+ρ)×ψ − C̃ε, ∇̇ = ε̇ = 0
//!   (+ white noise).
//! * Measurement (paper eqs. 15–18, verified in `sighting-model`): for each of the three
//!   landmarks the camera is pointed with the INS's position and attitude; z = (w, h) ∈ ℝ⁶ is
//!   simulated with the **nonlinear** model from the true and the computed states plus
//!   N(0, σ²_SD) noise (`[sighting] noise_var_m2`), and the filter uses z = H x + v with H
//!   (6×15, δp and ψ columns) evaluated at the computed position; R = `filter.r_var_m2` · I₆.
//!   Innovation ν = z − H x̂⁻ (the predicted offset of the computed state is zero).
//! * Filter (paper §5): discrete KF, Joseph update (`akf`). **Open loop** until
//!   `filter.open_loop_until_s` (paper: 195 s): x̂ is propagated and updated, the INS runs
//!   free. At every update at or after that time, **feedback**: δp̂, δv̂, ψ̂ are removed from the
//!   INS (`Strapdown::apply_correction`, exact in the contract's conventions), ∇̂, ε̂ are added
//!   to the INS's sensor corrections, x̂ ← 0 and P is kept (the reset is an identity on the
//!   error: INS error − x̂ is the same before and after, to first order; tested).
//!
//! ## Discretisation over the update interval (speed)
//!
//! The covariance is **not** propagated at 100 Hz. The filter predicts once per SD interval
//! T = 1 s with (Φ_T, Q_T) built by [`ins_sd_filter::interval`]: the interval is cut into
//! m = `filter.phi_subintervals` pieces (default 2, of 0.5 s); on each, the INS's
//! linearisation quantities (position, velocity, f_n = C̃ f_b, C̃) are averaged over its 100 Hz
//! steps, A is built from the averages, discretised by
//! `ins_errors::error_model::discretize_fast` (third-order series Φ, Simpson Q_d) and the
//! pieces are chained (Φ_T ← Φ_τ Φ_T, Q_T ← Φ_τ Q_T Φ_τᵀ + Q_τ). Measured against the paper's
//! way (product of the 100 Φ(0.01 s), Q_d per step accumulated; `tests/ins_sd_interval.rs`, in
//! a turn, across a manoeuvre boundary and in a climb): the Φ error in units of the states' σ,
//! max |ΔΦ_ij| σ_j/σ_i, is 2e-6 for m = 1, 3e-7 for m = 2, 1e-8 for m = 10; the predicted
//! variances agree to 1e-9 relative already for m = 1. m = 2 costs ≈ 1 % of a run; m = 10
//! would add ≈ 30 %.
//!
//! ## Process noise Q
//!
//! * **KF (manually tuned).** Continuous PSDs on the sensor inputs (`[filter]` `q_*`; white
//!   noise in per-sample variance like `[imu]`, PSD = variance · T_s; random walks in
//!   units²/s). W = G Q_c Gᵀ is constant because the PSDs are equal on the three body axes
//!   (C̃ q I C̃ᵀ = q I). Tuning, 20 seeded runs of 900 s per candidate, mean NEES (n = 15) over
//!   30–195 / 195–260 / 260–600 / 600–900 s:
//!
//!   | white noise (acc mg², gyro (°/h)²) | bias RW (mg²/s, (°/h)²/s) | NEES | RMS δp(900 s) |
//!   |---|---|---|---|
//!   | 1, 1 (true statistics) | 0, 0 | 13 / 20 / 16 / 17 | 0.8 m per axis |
//!   | **2, 2 (chosen)** | 0, 0 | 12 / 17 / 12 / 12 | 0.8 m |
//!   | 4, 4 | 0, 0 | 12 / 14 / 10 / 9 | 0.8 m |
//!   | 1, 1 | 0.01, 0 | 10 / 11 / 10 / 10 | 1.5 m |
//!
//!   With the true statistics the filter is over-confident just after the switch to feedback
//!   (the open-loop phase lets the INS errors reach hundreds of metres and ~1 mrad, and the
//!   second-order residue of the linear model is not in P); doubling the white-noise
//!   variances removes most of it without losing accuracy; more inflation, or any bias random
//!   walk, only makes the filter under-confident (and random walks double the error). NIS
//!   stays at 5.9–6.0 (m = 6) in all cases.
//! * **AKF.** Until N = `filter.akf_window` updates have been seen, the a-priori Q_T of the KF
//!   tuning is used. Afterwards the Mohamed–Schwarz estimate (paper eq. 19, `akf`)
//!   Q̂_k = (1/N) Σ Δx_j Δx_jᵀ + P_k⁺ − Φ_T P_{k−1}⁺ Φ_Tᵀ, with Φ_T the transition over the 1 s
//!   interval, is an estimate of the noise accumulated **over one interval** — exactly the
//!   Q_T the filter predicts with, since it predicts once per interval. So Q̂_k, made PSD
//!   (`filter.akf_projection`, default diagonal at `akf_min_variance` = 0), is used
//!   unchanged as Q_T of the next prediction; no conversion to a per-0.01 s Q_d is needed.
//!   (The paper's Φ of eq. 19 is discretised at T_s = 0.01 s, which would not span the
//!   interval between the Δx_j; with a 1 s interval Φ_T is the consistent reading.)
//!
//! **Results** (release, 100 runs per mode, `configs/paper.toml`): RMS over runs of δp at
//! 900 s — stand-alone 6.8 / 8.1 / 13.6 km (N/E/D; ψ_D 8.3 mrad), KF 0.84 / 0.90 / 0.80 m
//! (ψ ≈ 0.02–0.05 mrad), AKF (default, diagonal projection) 25 m 3-D (azimuth σ ≤ 0.51 mrad
//! after 600 s, NEES ≈ 6.4, NIS ≈ 5.3: under-confident, Q̂ too large). The paper reports
//! ≈ 100 m (KF) and ≈ 140 m (AKF): our KF is two orders of magnitude better than the paper's —
//! with σ_SD = 6.3 m and six observations per second the KF's own covariance predicts
//! metre-level errors and its NEES says the errors are that small. The paper's qualitative
//! claims hold: KF < AKF < stand-alone, AKF bounded, azimuth limited after 600 s.
//! The alternative `akf_projection = "eigen_clip"` (floor 0) gives 102 m RMS at 900 s — the
//! paper's order — but is not bounded: it is under-confident while
//! manoeuvring (mean NEES ≈ 6, NIS ≈ 3.3–4.3) and becomes badly over-confident after 600 s
//! (mean NEES ≈ 10³). Why (instrumented on run 96 of seed 2009, Q̂ diagonal against the KF's
//! a-priori Q_T): with N = 10 < 15 the sample term (1/N) Σ Δx Δxᵀ has rank ≤ 10, so Q̂ is
//! dominated by the indefinite P⁺ − Φ P⁺ Φᵀ; its raw ψ_D variance is ≈ −10⁶ × the model's.
//! Clipping 4–6 large negative eigenvalues to 0 adds their magnitude back as positive mass in
//! mixed-unit directions (m, m/s, rad, m/s², rad/s): the projected Q̂ has σ ≈ 10⁴ × the model's
//! on v and ψ already at 600 s. A larger Q̂ gives a larger P, a larger P⁺ − Φ P⁺ Φᵀ and larger
//! clipped mass — a positive feedback. In straight flight after 600 s the level/azimuth
//! direction (δp ≈ ρ ψ × u, landmarks ~10 km away) is weakly observable, P grows (position σ
//! 10 → 118 m at 600 → 720 s), the corrections fed back into the INS grow, and at 790–800 s Q̂
//! explodes (σ ≈ 1.5 km per interval on position, 10⁵–10⁶ × on v and ψ) while the updated P
//! stays at ~50 m: the error peaks at 6.8 km (NEES 10⁶) and then recovers (runs 96 / 31 / 74
//! peak at 6–7 km near 790–810 s, azimuth σ over runs 22 mrad at 792 s). The diagonal
//! projection sets a negative diagonal entry to 0 (4–11 of 15 at a time) and drops the cross
//! terms, adding no mass from the negative part: Q̂ stays at σ ≈ 10²–10³ × the model's (still
//! over-estimated, hence NEES ≈ 6) and the loop stays bounded (test
//! `default_akf_stays_bounded_where_eigen_clip_blows_up`).
//!
//! **The paper's printed H** (`[filter] measurement_jacobian`, hypothesis: the paper's KF
//! error of ≈ 0.1 km comes from running its filter with the printed, flawed eqs. 15–18). Same
//! 30 seeded runs (common random numbers), KF, RMS over runs of δp N / E / D:
//!
//! | `measurement_jacobian` | 195 s | 600 s | 900 s | mean NEES / NIS at 900 s |
//! |---|---|---|---|---|
//! | `"verified"` | 2.4 / 2.2 / 2.1 m | 1.0 / 1.0 / 1.0 m | 0.79 / 0.96 / 0.85 m | 10.7 / 6.4 |
//! | `"paper_printed_elevation"` (α₀ repaired, printed H₃) | 2.4 / 2.1 / 2.2 m | 1.0 / 1.0 / 1.0 m | 0.78 / 0.95 / 0.85 m | 10.7 / 6.4 |
//! | `"paper_printed"` (literal) | 366 / 262 / 1876 m | 124 / 102 / 185 km (23 runs alive) | 16.0 / 3.9 / 2.1 km (11 alive) | 4.9·10⁸ / 4.1·10⁵ |
//!
//! Read literally (α₀ = depression), the h rows are multiplied by cos 2ε: at the start the
//! steep landmark (ε ≈ 74°) has its h row sign-flipped and the 45° one has none. Already open
//! loop the estimate is off by hundreds of metres to kilometres (the recorded error is
//! INS − x̂, and the INS is the same in every setting until 195 s), the feedback then injects it
//! and the loop diverges: 19 of 30 runs end between 514 and 882 s with a landmark behind the
//! camera. The printed H₃ alone (with α₀ read as the elevation — which is also what the printed
//! α₀ means if its z axis is the paper's "up" state axis) changes nothing measurable. So the
//! printed H does **not** explain the paper's ≈ 0.1 km: literally it diverges, repaired it gives
//! our metre level. Reproduce: `cargo run --release -p ins-sim --example paper_h -- 30`, or
//! `cargo xtask monte-carlo --config <copy of configs/paper.toml with measurement_jacobian =
//! "paper_printed"> --runs 30` (same figures for the runs that finish; it excludes the failed
//! runs entirely, the example counts them up to their failure).
//!
//! **No feedback: the paper's order of magnitude, but on survivors.** With the verified H but
//! `open_loop_until_s` beyond the run (the INS is never corrected; the camera is pointed and H
//! is evaluated at the free INS, kilometres off by 600 s), 100 seeded runs (seed 2009, KF and
//! the AKF with the default diagonal projection, common random numbers;
//! `cargo xtask monte-carlo --sweep filter.open_loop_until_s=195,1e9`):
//!
//! | `open_loop_until_s` | filter | final 3-D median | 10–90 % | RMS | lost runs | NEES mean | epochs with NEES in band |
//! |---|---|---|---|---|---|---|---|
//! | 195 (paper) | KF | 1.3 m | 0.6–2.2 m | 1.5 m | 0 of 100 | 12.3 | 7 % |
//! | 195 (paper) | AKF | 19.0 m | 7.0–36.1 m | 25.4 m | 0 of 100 | 6.4 | 0 % |
//! | never | KF | 47 m | 12–151 m | 93 m | 38 of 100 (t = 450…886 s) | 6432 | 2 % |
//! | never | AKF | 66 m | 15–165 m | 107 m | 38 of 100 (t = 450…886 s) | 310 | 2 % |
//!
//! The statistics are over the surviving runs only: 38 of 100 runs are lost when the free INS
//! drifts (vertical channel) until a landmark is behind the camera, and the filter is badly
//! over-confident (NEES ≫ 15: the linearisation error at the drifted INS is not in P). So the
//! open-loop filter gives errors of the paper's order (≈ 0.1 km) with KF < AKF, but a figure
//! over 62 survivors is not a reproduction; an earlier 30-run look (96 m, 22 survivors, AKF
//! 177 m with the eigenvalue-clipping projection) overstated the match. What this supports is
//! only the reading of the paper's §7 remark that "H requires a rather accurate estimate of the
//! UAV position" as a filter linearised at an uncorrected INS — a hypothesis, not a finding.
//! (`cargo run --release -p ins-sim --example paper_h -- 30 open-loop`; with
//! `measurement_jacobian = "paper_printed"` open loop is 6.0 / 6.9 / 12.4 km at 900 s.)
//!
//! ## Randomness
//!
//! [`run_seed`] derives run i's seed from the master seed (SplitMix64, independent of threads
//! and order; it ignores the mode, so the three modes of one run index see the **same truth,
//! the same IMU error draw and the same IMU noise** — common random numbers, paired
//! comparisons). The IMU uses `ChaCha8Rng::seed_from_u64(seed)` exactly as a stand-alone
//! `ins-errors` run (draw ∇, ε, then per-step noise); the SD noise uses ChaCha stream 1 of the
//! same seed.
//!
//! ## Records
//!
//! [`Sample`]s at 1 Hz (t = 0 … duration; with an SD period other than 1 s, records between
//! updates carry the last posterior x̂, not a propagated one): error of the system's
//! navigation output (the INS
//! corrected by the current estimate: INS error − x̂; equal to the INS error in feedback and
//! stand-alone), ψ per the contract (from true and computed attitudes and the frame tilt δθ:
//! `ins_errors::error_model::error_state`), distance flown (truth, trapezoidal), and at SD
//! epochs NEES (all 15 states: true ∇, ε minus the sensor corrections applied so far, minus
//! x̂; against P⁺) and NIS (from the update).
//!
//! ## Errors
//!
//! One error type, [`SimError`], for everything the crate does; each variant says where it
//! failed and keeps the wrapped error typed as its `source`: the scenario
//! ([`SimError::ScenarioFile`]: file, line, column and dotted field, through `toml-config`;
//! [`SimError::ScenarioInvalid`]: the field of a scenario built in code), one run
//! ([`SimError::NonFinite`], [`SimError::Sighting`], [`SimError::Filter`],
//! [`SimError::Online`]: the time; [`SimError::OutputLength`], [`SimError::Ins`]), the logs
//! ([`SimError::LogParse`], [`SimError::LogToml`], [`SimError::LogFilter`], [`SimError::LogIo`],
//! [`SimError::LogWrite`], [`SimError::ExportRun`]: the file and, for content, the line and
//! column) and the statistics (`SimError::Stats*`: the field, the shard, the run ranges).
//! [`SimError::is_setup`] tells the errors that stop the run loop from those that exclude a run.
//!
//! ## Example
//!
//! ```
//! use ins_sim::{Mode, Sample, Scenario, run, run_seed};
//!
//! let scenario = Scenario::paper_default().truncated(20.0)?; // the first 20 s of the flight
//! let mut out = vec![Sample::default(); scenario.samples_per_run()];
//! let seed = run_seed(scenario.monte_carlo.seed, 0);
//! let outcome = run(&scenario, Mode::Kf, seed, &mut out)?;
//! assert_eq!(outcome.samples_written, 21);
//! assert!(out[20].nis.is_some()); // an SD update at t = 20 s
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod config;
mod engine;
mod error;
pub mod filter_file;
pub mod logs;
mod mismatch;
pub mod real_sets;
pub mod runs;
mod scenario;
pub mod stats;

pub use config::{
    AkfScheme, MeasurementJacobian, MismatchConfig, MonteCarloConfig, ScenarioFilterConfig,
};
pub use engine::{NoObserver, RunObserver};
pub use error::SimError;

pub use scenario::Scenario;

/// Simulation mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Stand-alone INS (no updates).
    Standalone,
    /// INS/SD with the manually tuned Kalman filter.
    Kf,
    /// INS/SD with the adaptive Kalman filter of `[filter] akf_scheme` / `akf_projection`
    /// (default: Mohamed & Schwarz, diagonal projection).
    Akf,
    /// Comparison: Sage–Husa with `[filter] sage_husa_forgetting` (warm-up `akf_window`) and
    /// `akf_projection`.
    #[serde(rename = "akf_sage_husa")]
    AkfSageHusa,
    /// Comparison: Mohamed–Schwarz (window `akf_window`) with the structured projection onto
    /// the model's noise inputs.
    #[serde(rename = "akf_structured")]
    AkfStructured,
}

impl Mode {
    /// The paper's three configurations, in report order (what `cargo xtask monte-carlo` runs).
    pub const ALL: [Mode; 3] = [Mode::Standalone, Mode::Kf, Mode::Akf];

    /// Every mode, in report order: the paper's three and the adaptive comparisons.
    pub const EVERY: [Mode; 5] = [
        Mode::Standalone,
        Mode::Kf,
        Mode::Akf,
        Mode::AkfSageHusa,
        Mode::AkfStructured,
    ];

    /// `"standalone"`, `"kf"`, `"akf"`, `"akf_sage_husa"` or `"akf_structured"`.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Standalone => "standalone",
            Mode::Kf => "kf",
            Mode::Akf => "akf",
            Mode::AkfSageHusa => "akf_sage_husa",
            Mode::AkfStructured => "akf_structured",
        }
    }

    /// The mode called `name` ([`Mode::name`]).
    pub fn from_name(name: &str) -> Option<Mode> {
        Mode::EVERY.into_iter().find(|m| m.name() == name)
    }

    /// Position in report order ([`Mode::EVERY`]).
    pub fn order(self) -> usize {
        self as usize
    }
}

/// Writes [`Mode::name`] (the text of the reports and of `stats.json`).
impl std::fmt::Display for Mode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

/// One 1 Hz record of one run (t = 0, 1, …, duration).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t_s: f64,
    /// Position error (computed − true), NED, m — of the navigation output (INS corrected by
    /// the current estimate; after the feedback correction if any).
    pub pos_err_ned_m: [f64; 3],
    /// Velocity error, NED, m/s (same convention).
    pub vel_err_ned_mps: [f64; 3],
    /// Misalignment ψ (contract), N, E, D components, rad.
    pub misalignment_rad: [f64; 3],
    /// True distance flown since t = 0, m.
    pub distance_m: f64,
    /// Filters only, at SD update epochs: eᵀ P⁻¹ e with all 15 states.
    pub nees: Option<f64>,
    /// Filters only, at SD update epochs: νᵀ S⁻¹ ν of the sightings used (6 measurements
    /// for three landmarks; see `nis_dof`).
    pub nis: Option<f64>,
    /// Degrees of freedom of `nis`: 2 × the sightings used at that epoch (0 when none).
    pub nis_dof: u32,
}

/// What a run did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SimRunOutcome {
    /// Records written to `out` (duration + 1 on success).
    pub samples_written: usize,
    /// 100 Hz IMU/INS steps simulated ("epochs" are the sighting epochs only).
    pub steps: u64,
    /// Sightings the filter used.
    pub sightings_used: u64,
    /// Sightings the filter's χ² gate rejected.
    pub sightings_rejected: u64,
}

/// Simulates one Monte Carlo run. `seed` fully determines the run. `out` has length
/// duration + 1 ([`Scenario::samples_per_run`]) and is caller-owned; the step loop does not
/// allocate.
pub fn run(
    scenario: &Scenario,
    mode: Mode,
    seed: u64,
    out: &mut [Sample],
) -> Result<SimRunOutcome, SimError> {
    engine::run(scenario, mode, seed, out)
}

/// Seed of run `index` derived from the master seed by SplitMix64, independent of threads
/// and order. It does not depend on the mode: all modes of one run index share truth, IMU
/// error draw and noise (common random numbers).
pub fn run_seed(master_seed: u64, index: u64) -> u64 {
    splitmix64(master_seed ^ splitmix64(index.wrapping_add(0x5851_F42D_4C95_7F2D)))
}

fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests;
