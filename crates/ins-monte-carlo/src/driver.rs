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
use ins_sim::runs::{Verdict, run_range};
use ins_sim::{Mode, Sample, SimError, SimRunOutcome};

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
    verdict: Result<Verdict, SimError>,
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

pub use ins_sim::stats::first_non_finite;

/// Simulates `plan.range` × `plan.modes` with `runner(mode, index, out)` and folds the records.
///
/// Each run is one call of the one run loop, [`ins_sim::runs::run_range`], on the rayon pool;
/// runs that its exclusion rule leaves out (a run that fails on its own, writes too few records
/// or holds a non-finite record) are excluded from the mode's statistics and listed (index, time,
/// reason); they are also reported through `progress.note` as they are folded. An invalid
/// scenario or a wrong buffer length aborts the whole simulation ([`McError::RunSetup`]: these
/// are not properties of one run).
pub fn simulate<F>(plan: &Plan, runner: F, progress: &dyn Progress) -> Result<Simulated, McError>
where
    F: Fn(Mode, u64, &mut [Sample]) -> Result<SimRunOutcome, SimError> + Sync,
{
    let pool = crate::pool(Some(plan.threads))?;
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
                    let mut verdict = None;
                    let result = run_range(
                        &runner,
                        plan.modes[mode_slot],
                        index..index + 1,
                        &mut samples,
                        |_, _, v| verdict = Some(v),
                    );
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
                        verdict: result.map(|()| {
                            verdict.unwrap_or(Verdict::Excluded {
                                steps: 0,
                                t_s: None,
                                reason: "the run loop returned no verdict".to_string(),
                            })
                        }),
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
            let verdict = match job.verdict {
                Ok(v) => v,
                Err(e) => {
                    progress.finish();
                    return Err(McError::RunSetup {
                        index: job.index,
                        mode: plan.modes[job.mode_slot],
                        source: Box::new(e),
                    });
                }
            };
            if let Some(e) =
                verdict.fold(job.index, &job.samples, stats, &mut runs, &mut exclusions)
            {
                progress.note(&format!(
                    "monte-carlo: run {} ({}) excluded{}: {}",
                    e.run_index,
                    e.mode,
                    e.t_s.map_or(String::new(), |t| format!(" at t = {t} s")),
                    e.reason
                ));
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
