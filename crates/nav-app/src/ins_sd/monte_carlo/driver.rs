//! Runs the simulations of one shard on a rayon pool and folds them, in run-index order, into
//! [`ModeStats`].
//!
//! Run indices are processed in blocks of `16 × threads`: the runs of a block (all modes) are
//! simulated in parallel, each into its own record buffer, then folded sequentially in
//! (index, mode) order. The statistics are therefore bit-identical for any thread count, and
//! memory stays bounded (one block of records) however many runs a shard holds.

use std::time::Instant;

use rayon::prelude::*;

use super::McError;
use super::stats::{Exclusion, ModeStats, RunSummary};
use crate::ins_sd::{Mode, RunError, RunOutcome, Sample};

/// Where the driver reports progress: the binary draws a progress bar, tests and the library
/// default stay [`Silent`]. Called from the worker threads (`run_done`) and from the folding
/// thread (`start`, `note`, `finish`).
pub trait Progress: Sync {
    /// The simulation starts: `total` runs (all configurations) to do.
    fn start(&self, _total: u64) {}
    /// One run finished (successfully or not).
    fn run_done(&self) {}
    /// A line for the user: a run excluded, a row of a table.
    fn note(&self, _line: &str) {}
    /// The simulation ended.
    fn finish(&self) {}
}

/// Reports nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Progress for Silent {}

/// What to simulate.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Modes, in report order.
    pub modes: Vec<Mode>,
    /// Records per run (duration + 1).
    pub samples: usize,
    /// Half-open range of run indices.
    pub range: (u64, u64),
    /// Worker threads (≥ 1).
    pub threads: usize,
}

/// The result of simulating a shard.
#[derive(Clone, Debug)]
pub struct Simulated {
    /// Per mode, in `Plan::modes` order.
    pub modes: Vec<ModeStats>,
    /// Runs left out, in (index, mode) order.
    pub exclusions: Vec<Exclusion>,
    /// Kept runs in brief, in (index, mode) order.
    pub runs: Vec<RunSummary>,
    /// Wall time of the simulation, s.
    pub wall_s: f64,
}

struct Job {
    index: u64,
    mode_slot: usize,
    samples: Vec<Sample>,
    result: Result<RunOutcome, RunError>,
    elapsed_s: f64,
    cpu_s: f64,
}

/// CPU time consumed by the calling thread, s (None where the platform has no such clock).
#[cfg(unix)]
pub fn thread_cpu_s() -> Option<f64> {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec for the duration of the call, and
    // CLOCK_THREAD_CPUTIME_ID is a clock every supported Unix provides.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    (rc == 0).then_some(ts.tv_sec as f64 + 1e-9 * ts.tv_nsec as f64)
}

/// CPU time consumed by the calling thread (not available on this platform).
#[cfg(not(unix))]
pub fn thread_cpu_s() -> Option<f64> {
    None
}

pub use crate::ins_sd::stats::first_non_finite;

/// Simulates `plan.range` × `plan.modes` with `runner(mode, index, out)` and folds the records.
///
/// Runs that fail ([`RunError::NonFinite`], a sighting or filter failure, …) or return a
/// non-finite record are excluded from the mode's statistics and listed (index, time, reason);
/// they are also reported through `progress.note` as they happen. An invalid scenario or a
/// wrong buffer length aborts the whole simulation ([`McError::RunSetup`]: these are not
/// properties of one run).
pub fn simulate<F>(plan: &Plan, runner: F, progress: &dyn Progress) -> Result<Simulated, McError>
where
    F: Fn(Mode, u64, &mut [Sample]) -> Result<RunOutcome, RunError> + Sync,
{
    let threads = super::thread_count(Some(plan.threads))?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let (lo, hi) = plan.range;
    progress.start((hi - lo) * plan.modes.len() as u64);

    let mut modes: Vec<ModeStats> = plan
        .modes
        .iter()
        .map(|&m| ModeStats::new(m, plan.samples))
        .collect();
    let mut exclusions = Vec::new();
    let mut runs = Vec::new();
    let block = 16 * plan.threads as u64;
    let start = Instant::now();
    let mut block_lo = lo;
    while block_lo < hi {
        let block_hi = (block_lo + block).min(hi);
        let jobs: Vec<(u64, usize)> = (block_lo..block_hi)
            .flat_map(|i| (0..plan.modes.len()).map(move |m| (i, m)))
            .collect();
        let done: Vec<Job> = pool.install(|| {
            jobs.par_iter()
                .map(|&(index, mode_slot)| {
                    let mut samples = vec![Sample::default(); plan.samples];
                    let t0 = Instant::now();
                    let c0 = thread_cpu_s();
                    let result = runner(plan.modes[mode_slot], index, &mut samples);
                    let elapsed_s = t0.elapsed().as_secs_f64();
                    let cpu_s = match (c0, thread_cpu_s()) {
                        (Some(a), Some(b)) => b - a,
                        _ => 0.0,
                    };
                    progress.run_done();
                    Job {
                        index,
                        mode_slot,
                        samples,
                        result,
                        elapsed_s,
                        cpu_s,
                    }
                })
                .collect()
        });
        for job in done {
            let stats = &mut modes[job.mode_slot];
            stats.run_time_s += job.elapsed_s;
            stats.run_cpu_s += job.cpu_s;
            let mode = plan.modes[job.mode_slot].name().to_string();
            let excluded = match job.result {
                Ok(outcome) => {
                    stats.epochs += outcome.epochs;
                    if outcome.samples_written != plan.samples {
                        Some((
                            None,
                            format!(
                                "run wrote {} of {} records",
                                outcome.samples_written, plan.samples
                            ),
                        ))
                    } else {
                        first_non_finite(&job.samples).map(|(t, what)| {
                            (Some(t), format!("non-finite {what} in the 1 Hz record"))
                        })
                    }
                }
                Err(e @ (RunError::Scenario(_) | RunError::OutputLength { .. })) => {
                    progress.finish();
                    return Err(McError::RunSetup {
                        index: job.index,
                        mode: plan.modes[job.mode_slot].name(),
                        source: Box::new(e),
                    });
                }
                Err(e) => {
                    let t = match &e {
                        RunError::NonFinite { t_s, .. }
                        | RunError::Sighting { t_s, .. }
                        | RunError::Filter { t_s, .. }
                        | RunError::Online { t_s, .. } => Some(*t_s),
                        _ => None,
                    };
                    Some((t, e.to_string()))
                }
            };
            match excluded {
                None => {
                    stats.push_run(&job.samples);
                    runs.push(RunSummary::of(
                        plan.modes[job.mode_slot],
                        job.index,
                        &job.samples,
                    ));
                }
                Some((t_s, reason)) => {
                    progress.note(&format!(
                        "monte-carlo: run {} ({mode}) excluded{}: {reason}",
                        job.index,
                        t_s.map_or(String::new(), |t| format!(" at t = {t} s"))
                    ));
                    exclusions.push(Exclusion {
                        mode,
                        run_index: job.index,
                        t_s,
                        reason,
                    });
                }
            }
        }
        block_lo = block_hi;
    }
    progress.finish();
    Ok(Simulated {
        modes,
        exclusions,
        runs,
        wall_s: start.elapsed().as_secs_f64(),
    })
}
