//! The one Monte Carlo run loop: runs run indices `a..b` of one mode one after the other into
//! a caller-owned record buffer and applies the one exclusion rule. The Monte Carlo driver (on
//! its rayon pool, one index per job), the model-mismatch table, the sweeps (crate
//! `ins-monte-carlo`) and the Python package all call [`run_range`]; nothing else runs Monte
//! Carlo runs.
//!
//! ## The exclusion rule
//!
//! A run is **excluded** from the statistics (and listed with its index, time and reason) when
//! * it fails on its own: [`SimError::NonFinite`], a sighting, filter or online-filter failure
//!   (the time of the failure is kept), or an `ins-errors` rejection;
//! * it returns but wrote fewer records than the buffer holds;
//! * any of its 1 Hz records holds a NaN/∞ ([`first_non_finite`]: position, velocity,
//!   misalignment, distance, NEES or NIS; the time of the first one is kept).
//!
//! An invalid scenario or a wrong buffer length ([`SimError::is_setup`]: a scenario error or
//! [`SimError::OutputLength`]) is not a property of one run: [`run_range`] stops and returns it.

use std::ops::Range;

use crate::stats::{Exclusion, ModeStats, RunSummary, first_non_finite};
use crate::{Mode, Sample, Scenario, SimError, SimRunOutcome};

/// What the one exclusion rule made of a run.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// The run is kept: its records are all finite.
    Kept(SimRunOutcome),
    /// The run is left out of the statistics.
    Excluded {
        /// IMU steps the run simulated before it was judged (0 when it failed with an error).
        steps: u64,
        /// When it failed or first held a non-finite record, s (if known).
        t_s: Option<f64>,
        /// What happened.
        reason: String,
    },
}

impl Verdict {
    /// IMU steps simulated (counted for the throughput, kept or not).
    pub fn steps(&self) -> u64 {
        match self {
            Verdict::Kept(o) => o.steps,
            Verdict::Excluded { steps, .. } => *steps,
        }
    }

    /// Applies the exclusion rule to what a run returned and the records it wrote into `out`.
    /// `Err` only for the errors that are not a property of one run (see the module doc).
    pub fn judge(
        result: Result<SimRunOutcome, SimError>,
        out: &[Sample],
    ) -> Result<Verdict, SimError> {
        match result {
            Ok(outcome) => Ok(if outcome.samples_written != out.len() {
                Verdict::Excluded {
                    steps: outcome.steps,
                    t_s: None,
                    reason: format!(
                        "run wrote {} of {} records",
                        outcome.samples_written,
                        out.len()
                    ),
                }
            } else if let Some((t, what)) = first_non_finite(out) {
                Verdict::Excluded {
                    steps: outcome.steps,
                    t_s: Some(t),
                    reason: format!("non-finite {what} in the 1 Hz record"),
                }
            } else {
                Verdict::Kept(outcome)
            }),
            Err(e) if e.is_setup() => Err(e),
            Err(e) => {
                let t_s = e.run_time_s();
                Ok(Verdict::Excluded {
                    steps: 0,
                    t_s,
                    reason: crate::error::with_causes(&e),
                })
            }
        }
    }

    /// Folds the run `index` of `stats.mode` (records `samples`) into the mode's statistics:
    /// kept → [`ModeStats::push_run`] and a [`RunSummary`] in `runs`; excluded → an
    /// [`Exclusion`] in `exclusions`, which is returned. The steps count either way.
    pub fn fold<'a>(
        &self,
        index: u64,
        samples: &[Sample],
        stats: &mut ModeStats,
        runs: &mut Vec<RunSummary>,
        exclusions: &'a mut Vec<Exclusion>,
    ) -> Option<&'a Exclusion> {
        stats.steps += self.steps();
        match self {
            Verdict::Kept(_) => {
                stats.push_run(samples);
                runs.push(RunSummary::of(stats.mode, index, samples));
                None
            }
            Verdict::Excluded { t_s, reason, .. } => {
                exclusions.push(Exclusion {
                    mode: stats.mode,
                    run_index: index,
                    t_s: *t_s,
                    reason: reason.clone(),
                });
                exclusions.last()
            }
        }
    }
}

/// The closed loop as a runner: run `index` of `mode` of `scenario` with the seed
/// [`crate::run_seed`]`(master_seed, index)`.
pub fn closed_loop(
    scenario: &Scenario,
    master_seed: u64,
) -> impl Fn(Mode, u64, &mut [Sample]) -> Result<SimRunOutcome, SimError> + Sync + '_ {
    move |mode, index, out| crate::run(scenario, mode, crate::run_seed(master_seed, index), out)
}

/// **The** Monte Carlo run loop: runs the indices `indices` of `mode` in order with `runner`
/// (normally [`closed_loop`]; tests pass stand-ins) into `out` (length: records per run), judges
/// each with the one exclusion rule ([`Verdict::judge`]) and hands `(index, records, verdict)`
/// to `done` before the next run overwrites the records. Returns the first error that is not a
/// property of one run (nothing after it is run).
pub fn run_range<R, F>(
    runner: &R,
    mode: Mode,
    indices: Range<u64>,
    out: &mut [Sample],
    mut done: F,
) -> Result<(), SimError>
where
    R: Fn(Mode, u64, &mut [Sample]) -> Result<SimRunOutcome, SimError> + ?Sized,
    F: FnMut(u64, &[Sample], Verdict),
{
    for index in indices {
        let result = runner(mode, index, out);
        let verdict = Verdict::judge(result, out)?;
        done(index, out, verdict);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Run i: finite records, except run 1 fails at 3 s, run 2 writes a NaN NEES at t = 2 s,
    /// run 3 writes one record too few, run 4 has a setup error.
    fn stand_in(_mode: Mode, index: u64, out: &mut [Sample]) -> Result<SimRunOutcome, SimError> {
        if index == 1 {
            return Err(SimError::NonFinite {
                t_s: 3.0,
                what: "INS position",
            });
        }
        if index == 4 {
            return Err(SimError::OutputLength {
                expected: 5,
                got: out.len(),
            });
        }
        for (t, s) in out.iter_mut().enumerate() {
            *s = Sample {
                t_s: t as f64,
                nees: Some(if index == 2 && t == 2 { f64::NAN } else { 15.0 }),
                ..Sample::default()
            };
        }
        Ok(SimRunOutcome {
            samples_written: out.len() - usize::from(index == 3),
            steps: 100,
            sightings_used: 0,
            sightings_rejected: 0,
        })
    }

    #[test]
    fn one_rule_excludes_failed_short_and_non_finite_runs_and_stops_on_setup_errors() {
        let mut out = vec![Sample::default(); 5];
        let mut seen = Vec::new();
        run_range(&stand_in, Mode::Kf, 0..4, &mut out, |i, _, v| {
            seen.push((i, v))
        })
        .unwrap();
        assert!(matches!(seen[0], (0, Verdict::Kept(_))));
        let why = |k: usize| match &seen[k].1 {
            Verdict::Excluded { t_s, reason, steps } => (*t_s, reason.clone(), *steps),
            Verdict::Kept(_) => panic!("run {k} kept"),
        };
        assert_eq!(why(1).0, Some(3.0));
        assert_eq!(why(1).2, 0, "a failed run counts no steps");
        assert_eq!(why(2).0, Some(2.0));
        assert!(why(2).1.contains("NEES"), "{}", why(2).1);
        assert_eq!((why(3).0, why(3).2), (None, 100));
        assert!(why(3).1.contains("4 of 5"), "{}", why(3).1);
        // A setup error is no run's property: the loop stops there.
        let mut n = 0;
        let e = run_range(&stand_in, Mode::Kf, 3..10, &mut out, |_, _, _| n += 1).unwrap_err();
        assert!(matches!(e, SimError::OutputLength { .. }));
        assert_eq!(n, 1, "only run 3 was handed over");
    }

    #[test]
    fn folding_counts_steps_and_lists_exclusions() {
        let mut out = vec![Sample::default(); 5];
        let mut st = ModeStats::new(Mode::Kf, 5);
        let (mut kept, mut excluded) = (Vec::new(), Vec::new());
        run_range(&stand_in, Mode::Kf, 0..4, &mut out, |i, out, v| {
            v.fold(i, out, &mut st, &mut kept, &mut excluded);
        })
        .unwrap();
        assert_eq!(st.runs_used, 1);
        assert_eq!(st.steps, 300, "runs 0, 2 and 3 returned; run 1 failed");
        assert_eq!(kept.len(), 1);
        let ex: Vec<u64> = excluded.iter().map(|e| e.run_index).collect();
        assert_eq!(ex, vec![1, 2, 3]);
        assert!(excluded.iter().all(|e| e.mode == Mode::Kf));
    }
}
