//! `nav-app ins`: replays an IMU log (with sightings, or unaided) through the online INS/SD
//! filter; `nav-app ins sightings`: writes sightings from a reference trajectory.

use std::io::BufWriter;
use std::path::{Path, PathBuf};

use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::Parser;
use ins_sim::Mode;
use ins_sim::filter_file::FilterFile;
mod layouts;

use ins_sim::logs::{
    self, FilterSettings, LosFrame, ReplayMetrics, ReplaySummary, SightingPlan, SolutionRate,
};
use layouts::{input_layouts, parse_rotation, write_tum_files};

/// `nav-app ins`: replay an IMU log through the INS/SD filter.
#[derive(Parser, Debug)]
#[command(
    name = "nav-app ins",
    bin_name = "nav-app ins",
    about = "Replays an IMU log, with landmark sightings or unaided, through the INS/SD filter \
             (formats: ins_sim::logs; `nav-app ins sightings --help` writes sightings from a \
             reference trajectory)",
    after_help = "The filter settings come from --config (a filter file in datasheet units, \
                  ins_sim::filter_file) or --preset (compiled in): mems, the default (sighting \
                  σ 1 m, gate 0.9999, feedback from the start), or paper (the paper's: sighting \
                  σ 6.32 m, no gate, feedback from 195 s after the start: a shorter log runs \
                  open loop throughout, and the replay warns). --print-config prints every \
                  setting in force; the replay's first line names the preset, σ, gate and \
                  feedback start. \
                  The initial state comes from --init, or from the reference (--truth) at \
                  --start-s (default: its first row). The IMU log, the reference and the \
                  sightings must overlap in time (an error names each file's first and last \
                  stamp); input rows not used are counted in the summary.\n\n\
                  Exit codes: 0 success; 1 error (a malformed log names its file, line and \
                  column); 2 bad command line."
)]
struct InsArgs {
    /// IMU log (CSV; header `t_s,dv_x_mps,…,dtheta_z_rad` for increments or
    /// `t_s,gyro_x_radps,…,accel_z_mps2` for rates; body FRD), a ROS 2 bag (`.mcap`) with a
    /// sensor_msgs/msg/Imu topic (ROS's FLU body axes are turned into FRD: y and z negated), or
    /// an EuRoC/ASL folder (`mav0`, or the folder holding it: `imu0/data.csv`, nanosecond
    /// stamps, ω then a, rotated into the body axes by --imu-to-body or its `sensor.yaml`'s
    /// T_BS).
    #[arg(long, value_name = "FILE", required_unless_present = "print_config")]
    imu: Option<PathBuf>,
    /// With an ASL folder: the rotation from the IMU's axes to the body's, C_B^S, as 9 numbers
    /// row-major (R11,R12,…,R33; default: T_BS of the folder's imu0/sensor.yaml).
    #[arg(long, value_name = "R11,…,R33")]
    imu_to_body: Option<String>,
    /// With a TUM or ASL reference (positions in a local frame): its origin, LAT,LON,ALT
    /// (degrees, degrees, m above the WGS-84 ellipsoid). Also the origin of --tum-out.
    #[arg(long, value_name = "LAT,LON,ALT", allow_hyphen_values = true)]
    tum_origin: Option<String>,
    /// The local frame's axes: enu (x east, y north, z up) or ned (x north, y east, z down);
    /// with --tum-origin for a TUM or ASL reference; for --tum-out alone, default enu.
    #[arg(long, value_name = "AXES", value_parser = ["enu", "ned"])]
    tum_frame: Option<String>,
    /// With a bag: the IMU topic (default: the bag's only sensor_msgs/msg/Imu topic).
    #[arg(long, value_name = "TOPIC")]
    imu_topic: Option<String>,
    /// Sightings log (CSV: `t_s,landmark_id,frame,los_x,los_y,los_z`, or the older
    /// `t_s,landmark_id,w_m,h_m`). Without it the INS runs unaided.
    #[arg(long, value_name = "FILE", requires = "landmarks")]
    sightings: Option<PathBuf>,
    /// Landmark table (TOML, [[landmarks]] id, lat_deg, lon_deg, alt_m).
    #[arg(long, value_name = "FILE")]
    landmarks: Option<PathBuf>,
    /// Initial INS state (TOML: t_s, lat_rad, lon_rad, alt_m, vel_ned_mps, att_quat_wxyz);
    /// default: from --truth at --start-s.
    #[arg(long, value_name = "FILE")]
    init: Option<PathBuf>,
    /// Start time of the replay when the initial state comes from --truth, s.
    #[arg(long, value_name = "S")]
    start_s: Option<f64>,
    /// Static alignment: the vehicle is at rest for this long after the start, s (at least 2).
    /// The rest is checked (the spread of the accelerometer's and gyro's 1-s means, and with
    /// --truth its speed, against the filter file's [align] limits) and the alignment refused
    /// otherwise. The mean rate over it (less the Earth rate) is the initial gyro bias; when
    /// the attitude did not come from a reference attitude, roll and pitch are levelled from
    /// the accelerometers. Moving at the start: leave it out (attitude from the reference).
    #[arg(long, value_name = "S", default_value_t = 0.0)]
    align_s: f64,
    /// Filter file (TOML, datasheet units; `preset = "mems"|"paper"` plus overrides). An older
    /// scenario file (with [trajectory]) is still accepted.
    #[arg(long, value_name = "FILE", conflicts_with = "preset")]
    config: Option<PathBuf>,
    /// Compiled-in filter settings: mems (consumer / industrial MEMS IMU) or paper.
    #[arg(long, value_name = "NAME")]
    preset: Option<String>,
    /// none (unaided INS), kf, akf (Mohamed–Schwarz), akf_sage_husa, akf_structured.
    #[arg(long, value_name = "NAME", default_value = "kf")]
    filter: String,
    /// With a filter (kf, akf…): accept a run that used no sighting (none in the replay's time
    /// span, or all rejected by the gate); without it such a run is an error.
    #[arg(long)]
    allow_unaided: bool,
    /// χ² gate probability per sighting (overrides the filter file's; 0 = no gate).
    #[arg(long, value_name = "P")]
    gate: Option<f64>,
    /// Longest IMU gap bridged by propagation, s (a longer one is an error).
    #[arg(long, value_name = "S", default_value_t = 5.0)]
    max_gap_s: f64,
    /// Solution rows at this rate, Hz (default: after every IMU sample).
    #[arg(long, value_name = "HZ")]
    rate: Option<f64>,
    /// Solution CSV to write.
    #[arg(long, value_name = "FILE", required_unless_present = "print_config")]
    out: Option<PathBuf>,
    /// Print the filter settings in force (the filter file or preset with --gate applied) as a
    /// filter file with units, to standard output, and exit; given back as --config it
    /// reproduces the run. Needs no other option.
    #[arg(long)]
    print_config: bool,
    /// Also write the solution with its σ, each epoch's NIS and (with --truth) the errors as
    /// JSON channels of an MCAP file, plottable in Foxglove (/ins/solution, /ins/epochs,
    /// /ins/errors, and the position as foxglove.LocationFix on /ins/fix for the Map panel).
    #[arg(long, value_name = "FILE")]
    mcap_out: Option<PathBuf>,
    #[command(flatten)]
    live: crate::live::LiveArgs,
    /// Reference trajectory: print and write the errors against it. CSV (radians or degrees,
    /// attitude optional), a TUM trajectory (`t x y z qx qy qz qw`, blank-separated, body →
    /// local quaternion) or an EuRoC/ASL folder's ground truth
    /// (state_groundtruth_estimate0/data.csv); the last two need --tum-origin and --tum-frame.
    #[arg(long, value_name = "FILE")]
    truth: Option<PathBuf>,
    /// Also write the solution as a TUM trajectory (`t x y z qx qy qz qw`, what `evo` reads):
    /// positions in a local frame (--tum-frame, default enu) with origin --tum-origin, default
    /// the first solution row; a header comment states the frame and origin.
    #[arg(long, value_name = "FILE")]
    tum_out: Option<PathBuf>,
    /// With --truth: the reference as a TUM trajectory in the same local frame, at the times
    /// the errors were computed (the rows of the printed RMS).
    #[arg(long, value_name = "FILE", requires = "truth")]
    tum_truth_out: Option<PathBuf>,
    /// With --truth: the error statistics as JSON.
    #[arg(long, value_name = "FILE", requires = "truth")]
    metrics_json: Option<PathBuf>,
    /// With --truth: a PNG of the errors (at the reference's rows) and their ±3σ envelopes
    /// (from the σ of each row of --out, so as many points as --rate writes).
    #[arg(long, value_name = "FILE", requires = "truth")]
    plot: Option<PathBuf>,
}

/// `nav-app ins sightings`: write sightings from a reference trajectory.
#[derive(Parser, Debug)]
#[command(
    name = "nav-app ins sightings",
    bin_name = "nav-app ins sightings",
    about = "Writes a pointed-sightings log from a reference trajectory and a landmark table \
             (ins_sim::logs::write_sightings): by default body directions when the reference has \
             an attitude, local-level (NED) ones otherwise, or the frame --frame asks for; \
             seeded."
)]
struct SightingsArgs {
    /// Reference trajectory: CSV (radians or degrees, attitude optional), a TUM trajectory or an
    /// EuRoC/ASL folder's ground truth (the last two with --tum-origin and --tum-frame, as for
    /// `nav-app ins --truth`).
    #[arg(long, value_name = "FILE")]
    reference: PathBuf,
    /// With a TUM or ASL reference: its local frame's origin, LAT,LON,ALT (degrees, degrees, m).
    #[arg(
        long,
        value_name = "LAT,LON,ALT",
        allow_hyphen_values = true,
        requires = "tum_frame"
    )]
    tum_origin: Option<String>,
    /// With an ASL folder's ground truth: the rotation IMU → body, as for `nav-app ins`
    /// (default: the folder's imu0/sensor.yaml, else the identity), so that body directions are
    /// in the body axes the replay uses.
    #[arg(long, value_name = "R11,…,R33")]
    imu_to_body: Option<String>,
    /// With --tum-origin: the local frame's axes, enu or ned.
    #[arg(long, value_name = "AXES", value_parser = ["enu", "ned"], requires = "tum_origin")]
    tum_frame: Option<String>,
    /// Landmark table to read, or with --make-landmarks to write.
    #[arg(long, value_name = "FILE")]
    landmarks: PathBuf,
    /// Place this many landmarks around the reference (seeded) and write them to --landmarks.
    #[arg(long, value_name = "N")]
    make_landmarks: Option<usize>,
    /// With --make-landmarks: their horizontal distance from the trajectory, m (MIN MAX).
    #[arg(long, value_names = ["MIN", "MAX"], num_args = 2, default_values_t = [50.0, 300.0])]
    landmark_range_m: Vec<f64>,
    /// Sightings log to write.
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// σ of w and h, m at the landmark.
    #[arg(long, value_name = "M", default_value_t = 1.0)]
    sigma_m: f64,
    /// Time between epochs, s.
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    period_s: f64,
    /// Nearest slant range sighted, m.
    #[arg(long, value_name = "M", default_value_t = 1.0)]
    min_range_m: f64,
    /// Farthest slant range sighted, m.
    #[arg(long, value_name = "M", default_value_t = 1000.0)]
    max_range_m: f64,
    /// Half-angle of the field of regard about the forward axis, ° (180 = all around).
    #[arg(long, value_name = "DEG", default_value_t = 180.0)]
    field_of_regard_deg: f64,
    /// At most this many (the nearest) landmarks per epoch.
    #[arg(long, value_name = "N", default_value_t = 6)]
    max_per_epoch: usize,
    /// Seed of the noise (and of the landmark placement).
    #[arg(long, value_name = "N", default_value_t = 1)]
    seed: u64,
    /// The frame of the directions written: body (FRD; needs the reference's attitude in every
    /// row) or ned (local level). Default: body when the reference has an attitude in every
    /// row, else ned. The same seed gives the same draws in either frame.
    #[arg(long, value_name = "FRAME", value_parser = ["body", "ned"])]
    frame: Option<String>,
}

/// Where the settings come from, for `--print-config` and the replay's header line.
fn settings_origin(args: &InsArgs, settings: &FilterSettings) -> String {
    match (settings, &args.config) {
        (FilterSettings::File(f), Some(path)) => {
            format!("{} over preset {}", path.display(), f.preset)
        }
        (FilterSettings::File(f), None) => format!("preset {}", f.preset),
        (FilterSettings::Scenario(_), path) => format!(
            "the [filter] of scenario {}",
            path.as_deref().unwrap_or(Path::new("")).display()
        ),
    }
}

/// `--print-config`: the settings in force as a filter file, on standard output.
fn print_config(args: &InsArgs) -> Result<()> {
    let settings = filter_settings(args)?;
    let FilterSettings::File(file) = &settings else {
        bail!(
            "--print-config: {} is a simulation scenario (the older way), not a filter file; \
             its filter settings are its [filter] section",
            args.config.as_deref().unwrap_or(Path::new("")).display()
        );
    };
    let mut origin = settings_origin(args, &settings);
    let file = match args.gate {
        Some(p) => {
            origin += &format!(", --gate {p}");
            file.with_gate(p)?
        }
        None => *file,
    };
    print!("{}", file.to_toml(&origin));
    Ok(())
}

fn filter_settings(args: &InsArgs) -> Result<FilterSettings> {
    if let Some(path) = &args.config {
        let text =
            std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
        // A filter file, or an older scenario file (a top-level [trajectory]): its [filter].
        return Ok(FilterSettings::from_toml_named(
            &path.display().to_string(),
            &text,
        )?);
    }
    Ok(FilterSettings::File(FilterFile::preset(
        args.preset.as_deref().unwrap_or("mems"),
    )?))
}

fn run_ins(args: &InsArgs) -> Result<()> {
    if args.print_config {
        return print_config(args);
    }
    // clap requires both unless --print-config.
    let (Some(imu), Some(out_path)) = (&args.imu, &args.out) else {
        bail!("give --imu FILE and --out FILE (or --print-config)");
    };
    let mode = Mode::from_name(&args.filter)
        .or((args.filter == "none").then_some(Mode::Standalone))
        .with_context(|| {
            format!(
                "--filter: `{}` is not none, kf, akf, akf_sage_husa or akf_structured",
                args.filter
            )
        })?;
    if mode == Mode::Standalone && args.sightings.is_some() {
        eprintln!(
            "nav-app ins: warning: --filter none runs the INS unaided: the sightings ({}) are ignored",
            args.sightings.as_deref().unwrap_or(Path::new("")).display()
        );
    }
    if mode != Mode::Standalone && args.sightings.is_none() {
        bail!(
            "--filter {}: give --sightings and --landmarks, or --filter none",
            args.filter
        );
    }
    let request = logs::ReplayRequest {
        imu: imu.clone(),
        imu_topic: args.imu_topic.clone(),
        sightings: args.sightings.clone().zip(args.landmarks.clone()),
        initial: args.init.clone(),
        reference: args.truth.clone(),
        start_s: args.start_s,
        settings: filter_settings(args)?,
        mode,
        gate: args.gate.map(|p| (p != 0.0).then_some(p)),
        align_s: args.align_s,
        allow_unaided: args.allow_unaided,
        max_gap_s: args.max_gap_s,
        rate: args.rate.map_or(SolutionRate::EveryImu, SolutionRate::Hz),
        mcap_out: args.mcap_out.clone(),
        layouts: input_layouts(args)?,
    };
    if args.init.is_none() && args.truth.is_none() {
        bail!("the initial state: give --init FILE, or --truth FILE to take it from the reference");
    }
    let inputs = request.inputs()?;
    let reference = args
        .tum_truth_out
        .as_ref()
        .and(inputs.reference.as_ref())
        .map(|(_, rows)| rows.clone());
    let feedback_t_s = inputs.config.open_loop_until_s;
    eprintln!(
        "nav-app ins: settings: {}; --filter {}; sighting σ {:.3} m; gate {}; feedback from t = {:.3} s ({:.3} s after the start){}",
        settings_origin(args, &request.settings),
        args.filter,
        inputs.config.r_var_m2.sqrt(),
        inputs
            .config
            .gate_probability
            .map_or("none".to_owned(), |p| format!("{p}")),
        feedback_t_s,
        feedback_t_s - inputs.initial.t_s,
        if args.config.is_some() || args.preset.is_some() {
            ""
        } else {
            " (all settings: --print-config)"
        }
    );
    let file = std::fs::File::create(out_path)
        .with_context(|| format!("creating {}", out_path.display()))?;
    let mut out = BufWriter::new(file);
    let live = match &args.live.foxglove {
        Some(addr) => Some(crate::live::Live::start(addr, &logs::ins_channels())?),
        None => None,
    };
    if live.is_some() || args.live.realtime {
        crate::live::install_sigint();
    }
    if let Some(l) = &live {
        eprintln!("nav-app ins: serving Foxglove on ws://{}", l.addr());
        if args.live.wait_client {
            eprintln!("nav-app ins: waiting for a client to subscribe (--wait-client)");
            l.wait_client();
        }
    }
    let mut tap = crate::live::InsTap {
        live: live.as_ref(),
        pacer: args.live.realtime.then(crate::live::Pacer::default),
    };
    let replayed = logs::replay_with_tap(inputs, &mut out, out_path, Some(&mut tap));
    if let Some(l) = live {
        let f = l.shutdown();
        eprintln!(
            "nav-app ins: Foxglove: {} clients, {} messages sent, {} dropped",
            f.clients, f.sent, f.dropped
        );
    }
    if crate::live::interrupted() {
        eprintln!("nav-app ins: interrupted (Ctrl-C): the replay ended there");
    }
    let summary = match replayed {
        Ok(summary) => summary,
        Err(e) => {
            // A refused or failed run leaves no solution behind that could pass for one (the
            // rows before the refusal); a device or a symlink such as /dev/stdout is left alone.
            drop(out);
            if std::fs::symlink_metadata(out_path).is_ok_and(|m| m.is_file()) {
                let _ = std::fs::remove_file(out_path);
            }
            return Err(e.into());
        }
    };
    if mode != Mode::Standalone && summary.end_t_s < feedback_t_s {
        eprintln!(
            "nav-app ins: warning: the IMU log ends at t = {:.3} s, before feedback starts at t = {:.3} s (filter.feedback_from_s after the start): the filter ran open loop throughout, its estimates never corrected the INS; lower feedback_from_s in a filter file (--print-config prints the settings in force)",
            summary.end_t_s, feedback_t_s
        );
    }
    report(args, out_path, &summary)?;
    write_tum_files(
        args,
        &request.layouts,
        out_path,
        reference.as_deref(),
        &summary,
    )
}

/// The input rows not used, as one clause of the summary line.
fn unused_text(args: &InsArgs, s: &ReplaySummary) -> String {
    let u = &s.unused;
    let mut text = format!(
        "rows not used: IMU {} at or before the start",
        u.imu_before_start
    );
    if s.spans.iter().any(|p| p.role == "sightings") {
        text += &format!(
            ", sightings {} at or before the start and {} after the IMU's end",
            u.sightings_before_start, u.sightings_after_end
        );
    }
    if args.truth.is_some() {
        text += &format!(
            ", reference {} before the start and {} after the IMU's end",
            u.reference_before_start, u.reference_after_end
        );
    }
    text
}

fn report(args: &InsArgs, out_path: &Path, s: &ReplaySummary) -> Result<()> {
    eprintln!(
        "nav-app ins: {} IMU samples to t = {:.3} s from the start at t = {:.3} s (the first {:.3} s after it), {} IMU gaps bridged (longest {:.3} s), {} sighting epochs, {} sightings used, {} rejected by the gate; {}; wrote {}",
        s.imu_samples,
        s.end_t_s,
        s.start_t_s,
        s.lead_in_s,
        s.gaps,
        s.longest_gap_s,
        s.epochs,
        s.sightings_used,
        s.sightings_rejected,
        unused_text(args, s),
        out_path.display()
    );
    if let Some(a) = &s.alignment {
        let [x, y, z] = a.gyro_bias_body_radps;
        eprintln!(
            "nav-app ins: aligned on {} samples at rest (spread of the 1-s means: accelerometer {:.4} m/s², gyro {:.4} °/s{}): gyro bias ({:.4}, {:.4}, {:.4}) °/s{}",
            a.samples,
            a.accel_spread_mps2,
            a.gyro_spread_radps.to_degrees(),
            a.reference_max_speed_mps
                .map_or(String::new(), |v| format!("; reference speed ≤ {v:.3} m/s")),
            x.to_degrees(),
            y.to_degrees(),
            z.to_degrees(),
            a.roll_pitch_rad.map_or(String::new(), |[r, p]| format!(
                ", levelled to roll {:.2}°, pitch {:.2}°",
                r.to_degrees(),
                p.to_degrees()
            ))
        );
    }
    if s.offset_sightings {
        eprintln!(
            "nav-app ins: note: the sightings are offsets (t_s,landmark_id,w_m,h_m): they mean what they say only to the filter that pointed the device"
        );
    }
    let (Some(truth), Some(m)) = (&args.truth, &s.metrics) else {
        return Ok(());
    };
    if m.compared == 0 {
        bail!("{}: no reference row inside the replay", truth.display());
    }
    print_metrics(truth, m);
    if let Some(path) = &args.metrics_json {
        let json = serde_json::json!({
            "schema": 1,
            "filter": args.filter,
            "imu_samples": s.imu_samples,
            "epochs": s.epochs,
            "sightings_used": s.sightings_used,
            "sightings_rejected": s.sightings_rejected,
            "lead_in_s": s.lead_in_s,
            "gaps": s.gaps,
            "longest_gap_s": s.longest_gap_s,
            "start_t_s": s.start_t_s,
            "end_t_s": s.end_t_s,
            "unused": s.unused,
            "inputs": s.spans,
            "alignment": s.alignment,
            "metrics": m,
        });
        std::fs::write(path, serde_json::to_string_pretty(&json)? + "\n")
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.plot {
        // The reference named by its last two path components (e.g. `euroc_mh01/truth.csv`).
        let parts: Vec<_> = truth.components().rev().take(2).collect();
        let name: PathBuf = parts.iter().rev().collect();
        let title = format!("--filter {} against {}", args.filter, name.display());
        // The envelopes from the σ of each solution row, as written.
        let rows = logs::read_solution_sigma(out_path)?;
        let png = ins_plot::replay_figure(&m.series, &rows, &title)?;
        std::fs::write(path, png).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

fn print_metrics(truth: &Path, m: &ReplayMetrics) {
    let line = |what: &str, unit: &str, e: &logs::ErrorStats, scale: f64| {
        eprintln!(
            "  {what:<9} RMS {:>9.3} {unit}, max {:>9.3} {unit}, last {:>9.3} {unit}; inside 2σ: {:>5.1} % of epochs (3-D), {:>5.1} % of axes",
            e.rms * scale,
            e.max * scale,
            e.last * scale,
            100.0 * e.inside_2sigma_epochs,
            100.0 * e.inside_2sigma
        );
    };
    eprintln!(
        "nav-app ins: against {} ({} times, {:.1}–{:.1} s):",
        truth.display(),
        m.compared,
        m.span_s[0],
        m.span_s[1]
    );
    line("position", "m", &m.position_m, 1.0);
    line("velocity", "m/s", &m.velocity_mps, 1.0);
    if let Some(a) = &m.attitude_rad {
        line("attitude", "mrad", a, 1e3);
    }
    if let Some(n) = m.nees_per_dof {
        let band = match (
            m.nees_band_95,
            m.nees_effective_times,
            m.nees_autocorrelation_times,
        ) {
            (Some([lo, hi]), Some(n_eff), Some(tau)) => format!(
                "; the times are correlated (autocorrelation time {tau:.1} times): as {n_eff:.1} independent ones, χ² 95 % band {lo:.3}–{hi:.3}{}",
                m.nees_band_95_if_independent
                    .map_or(String::new(), |[lo, hi]| format!(
                        " ({lo:.3}–{hi:.3} if they were independent)"
                    ))
            ),
            _ => String::new(),
        };
        eprintln!(
            "  NEES per dof {n:.3} over {} dof at {} times{band}",
            m.nees_dof, m.nees_times
        );
    }
    if let Some(n) = m.nis_per_dof {
        eprintln!(
            "  NIS per dof {n:.3} over {} dof{}",
            m.nis_dof,
            m.nis_band_95.map_or(String::new(), |[lo, hi]| format!(
                " (χ² 95 % band {lo:.3}–{hi:.3}, the epochs taken as independent: a consistent filter's innovations are white)"
            ))
        );
    }
}

fn run_sightings(args: &SightingsArgs) -> Result<()> {
    let local = match (&args.tum_origin, &args.tum_frame) {
        (Some(origin), Some(axes)) => Some(logs::LocalFrame::from_text(
            origin,
            logs::LocalAxes::parse(axes).context("--tum-frame: enu or ned")?,
        )?),
        _ => None,
    };
    if local.is_some() && !logs::is_local_reference(&args.reference)? {
        bail!(
            "--tum-origin: {} is a CSV reference (geodetic): it has no local frame",
            args.reference.display()
        );
    }
    let given = parse_rotation(args.imu_to_body.as_deref())?;
    // An ASL folder: its IMU's rotation as the replay takes it (given, else sensor.yaml).
    let folder_imu = Some(&args.reference)
        .filter(|p| p.is_dir())
        .and_then(|p| logs::asl_imu_file(p));
    let body_from_imu = match (folder_imu, given) {
        (Some(imu), given) if given.is_some() || imu.with_file_name("sensor.yaml").is_file() => {
            Some(logs::asl_body_from_imu(&imu, given)?)
        }
        (None, Some(_)) => {
            bail!("--imu-to-body: applies to an EuRoC/ASL folder's ground truth (--reference DIR)")
        }
        _ => None,
    };
    let reference =
        logs::read_reference_in(&args.reference, local.as_ref(), body_from_imu.as_ref())?;
    if let Some(n) = args.make_landmarks {
        let (lo, hi) = (args.landmark_range_m[0], args.landmark_range_m[1]);
        let entries = logs::landmarks_around(&reference, n, lo, hi, args.seed)?;
        logs::write_landmarks(&args.landmarks, &entries)?;
        eprintln!(
            "nav-app ins sightings: wrote {n} landmarks to {}",
            args.landmarks.display()
        );
    }
    let table = logs::read_landmarks(&args.landmarks)?;
    let plan = SightingPlan {
        sigma_m: args.sigma_m,
        period_s: args.period_s,
        min_range_m: args.min_range_m,
        max_range_m: args.max_range_m,
        field_of_regard_deg: args.field_of_regard_deg,
        max_per_epoch: args.max_per_epoch,
        seed: args.seed,
        frame: args.frame.as_deref().and_then(LosFrame::parse),
        ..SightingPlan::default()
    };
    let file = std::fs::File::create(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let w = logs::write_sightings(
        &reference,
        &table,
        &plan,
        &mut BufWriter::new(file),
        &args.out,
    )?;
    eprintln!(
        "nav-app ins sightings: {} epochs, {} sightings ({} directions), at least {} landmarks per epoch, {} epochs with none in view; wrote {}",
        w.epochs,
        w.sightings,
        if w.frame_is_body {
            "body"
        } else {
            "local-level"
        },
        w.min_per_epoch,
        w.empty_epochs,
        args.out.display()
    );
    Ok(())
}

/// `nav-app ins …` (`args` from the subcommand's name on); returns the process exit code.
pub fn main(args: impl IntoIterator<Item = std::ffi::OsString>) -> ExitCode {
    let args: Vec<std::ffi::OsString> = args.into_iter().collect();
    let result = if args.get(1).is_some_and(|a| a == "sightings") {
        let parsed = SightingsArgs::parse_from(args.iter().skip(1));
        run_sightings(&parsed).map_err(|e| ("nav-app ins sightings", e))
    } else {
        run_ins(&InsArgs::parse_from(&args)).map_err(|e| ("nav-app ins", e))
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err((who, e)) => {
            eprintln!("{who}: error: {}", crate::error_chain(e.as_ref()));
            ExitCode::from(1)
        }
    }
}
