//! `nav-app ins`: replays IMU and sighting logs through the online INS/SD filter.

use std::io::BufWriter;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::Parser;

/// `nav-app ins`: replay IMU and sighting logs through the online INS/SD filter.
#[derive(Parser, Debug)]
#[command(
    name = "nav-app ins",
    about = "Replays IMU and sighting logs through the INS/SD filter (formats: ins_sim::logs)",
    after_help = "All of --imu, --sightings, --landmarks, --init and --out are required (there is no \
                  bundled flight; `nav-app monte-carlo --export-logs DIR` writes one). \
                  --config defaults to configs/paper.toml.\n\n\
                  Exit codes: 0 success; 1 error (a malformed log names its file, line and column); \
                  2 bad command line."
)]
struct InsArgs {
    /// IMU log (CSV: t_s, Δv body m/s, Δθ body rad).
    #[arg(long, value_name = "FILE")]
    imu: PathBuf,
    /// Sightings log (CSV: t_s, landmark_id, w_m, h_m).
    #[arg(long, value_name = "FILE")]
    sightings: PathBuf,
    /// Landmark table (TOML, [[landmarks]] id, lat_deg, lon_deg, alt_m).
    #[arg(long, value_name = "FILE")]
    landmarks: PathBuf,
    /// Initial INS state (TOML: t_s, lat_rad, lon_rad, alt_m, vel_ned_mps, att_quat_wxyz).
    #[arg(long, value_name = "FILE")]
    init: PathBuf,
    /// Scenario file for the filter settings ([filter], [sighting] update_period_s,
    /// [trajectory] step_s).
    #[arg(long, value_name = "FILE", default_value = "configs/paper.toml")]
    config: PathBuf,
    /// Filter: kf (tuned KF) or akf (Mohamed–Schwarz adaptive KF).
    #[arg(long, value_name = "kf|akf", default_value = "kf")]
    filter: String,
    /// χ² innovation gate probability per sighting (e.g. 0.9999); no gate when absent.
    #[arg(long, value_name = "P")]
    gate: Option<f64>,
    /// Solution CSV to write.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// Truth CSV: print the solution's errors against it.
    #[arg(long, value_name = "FILE")]
    truth: Option<PathBuf>,
}

fn run_ins(args: &InsArgs) -> Result<()> {
    use ins_sim::{Mode, Scenario, logs};
    let text = std::fs::read_to_string(&args.config)
        .with_context(|| format!("reading {}", args.config.display()))?;
    let scenario = Scenario::from_toml_str(&text)
        .with_context(|| format!("scenario {}", args.config.display()))?;
    let mode = match args.filter.as_str() {
        "kf" => Mode::Kf,
        "akf" => Mode::Akf,
        other => bail!("--filter: `{other}` is not kf or akf"),
    };
    let mut config = scenario.online_filter_config(mode);
    config.gate_probability = args.gate;
    let inputs = logs::ReplayInputs {
        imu: args.imu.clone(),
        sightings: args.sightings.clone(),
        landmarks: args.landmarks.clone(),
        initial: args.init.clone(),
        config,
    };
    let file = std::fs::File::create(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let mut out = BufWriter::new(file);
    let summary = logs::replay(&inputs, &mut out, &args.out)?;
    eprintln!(
        "nav-app ins: {} IMU samples, {} sighting epochs, {} sightings used, {} rejected by the gate; wrote {}",
        summary.imu_samples,
        summary.epochs,
        summary.sightings_used,
        summary.sightings_rejected,
        args.out.display()
    );
    if let Some(truth) = &args.truth {
        let c = logs::compare_with_truth(truth, &summary.solution)?;
        if c.matched == 0 {
            bail!("{}: no truth row at the solution's times", truth.display());
        }
        let [n, e, d] = c.last_pos_err_ned_m;
        let [pn, pe, pd] = c.last_psi_rad;
        eprintln!(
            "nav-app ins: against {} ({} epochs): at t = {} s position error N {n:.3} m, E {e:.3} m, D {d:.3} m (3-D {:.3} m), misalignment {:.4} / {:.4} / {:.4} mrad; 3-D RMS {:.3} m, max {:.3} m",
            truth.display(),
            c.matched,
            c.last_t_s,
            (n * n + e * e + d * d).sqrt(),
            pn * 1e3,
            pe * 1e3,
            pd * 1e3,
            c.rms_pos_3d_m,
            c.max_pos_3d_m
        );
    }
    Ok(())
}

/// `e` and its sources as `anyhow`'s `{:#}` shows them (`e: cause: cause`), leaving out a cause
/// whose text is already shown: `ins_sim::SimError` keeps located errors (the TOML loader's,
/// the filter's) as typed `#[source]`s and also shows them, and a file, line and column are
/// to be named once.
pub(crate) fn error_chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut shown = e.to_string();
    let mut next = e.source();
    while let Some(cause) = next {
        let text = cause.to_string();
        if !shown.contains(&text) {
            shown.push_str(": ");
            shown.push_str(&text);
        }
        next = cause.source();
    }
    shown
}

/// `nav-app ins …` (`args` from the subcommand's name on); returns the process exit code.
pub fn main(args: impl IntoIterator<Item = std::ffi::OsString>) -> ExitCode {
    let args = InsArgs::parse_from(args);
    match run_ins(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("nav-app ins: error: {}", error_chain(e.as_ref()));
            ExitCode::from(1)
        }
    }
}
