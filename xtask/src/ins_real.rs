//! `cargo xtask ins-real`: the INS/SD filter on the real IMU logs under the data root
//! (`--data DIR`, default `ins/` under `$ITA_NAV_DATA` or `../shared/data`; third-party, never in
//! the repository), through the product binary exactly as a user runs it: `nav-app ins sightings`
//! writes landmarks and sightings from each reference (σ 1 m, 1 Hz, seeded;
//! `ins_sim::real_sets`), then `nav-app ins` replays unaided, KF and AKF with the `mems` preset
//! and KF and AKF with the `paper` preset. Writes `summary.md` (the table of docs/results/ins.md), each
//! run's `--metrics-json`, and the error plots of the KF on the `mems` preset
//! (`<set>_kf_mems.png`) into `--out` (default `target/ins-real`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use ins_sim::real_sets::{REAL_SEED, REAL_SETS};

use crate::paths::{build_nav_app_release, workspace_root};

/// Arguments of `cargo xtask ins-real`.
#[derive(clap::Args, Debug)]
pub struct InsRealArgs {
    /// Directory holding the sets (`<set>/imu.csv`, `<set>/truth.csv`). Default: `ins/` under
    /// the data root.
    #[arg(long)]
    data: Option<PathBuf>,
    /// Output directory (relative paths are taken from the workspace root).
    #[arg(long, default_value = "target/ins-real")]
    out: PathBuf,
}

fn data_root() -> PathBuf {
    match std::env::var_os("ITA_NAV_DATA") {
        Some(d) => PathBuf::from(d),
        None => workspace_root().join("../shared/data"),
    }
}

fn nav_app(exe: &Path, args: &[String]) -> Result<()> {
    let out = Command::new(exe)
        .args(args)
        .output()
        .with_context(|| format!("cannot run {}", exe.display()))?;
    if !out.status.success() {
        bail!(
            "nav-app {} failed ({}):\n{}",
            args.join(" "),
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
    }
    Ok(())
}

fn fmt_cell(v: &serde_json::Value, path: &[&str], scale: f64, digits: usize) -> String {
    let mut x = v;
    for p in path {
        x = &x[*p];
    }
    x.as_f64()
        .map_or("–".to_owned(), |f| format!("{:.*}", digits, f * scale))
}

/// Builds `nav-app` and runs the sets.
pub fn run(args: InsRealArgs) -> Result<()> {
    let root = workspace_root();
    let data = args.data.unwrap_or_else(|| data_root().join("ins"));
    let out = if args.out.is_absolute() {
        args.out.clone()
    } else {
        root.join(&args.out)
    };
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let exe = build_nav_app_release(&root)?;
    let mut md = String::from(
        "| set | filter | preset | position RMS / max (m) | velocity RMS (m/s) | attitude RMS (mrad) | epochs inside 2σ pos / vel / att (%) | NIS per dof | NEES per dof |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut ran = 0;
    for set in &REAL_SETS {
        let dir = data.join(set.name);
        let (imu, truth) = (dir.join("imu.csv"), dir.join("truth.csv"));
        if !imu.is_file() || !truth.is_file() {
            eprintln!(
                "ins-real: SKIPPED {}: no imu.csv / truth.csv in {}",
                set.name,
                dir.display()
            );
            continue;
        }
        ran += 1;
        let s = |p: &Path| p.display().to_string();
        let lm = out.join(format!("{}_landmarks.toml", set.name));
        let sightings = out.join(format!("{}_sightings.csv", set.name));
        nav_app(
            &exe,
            &[
                "ins".into(),
                "sightings".into(),
                "--reference".into(),
                s(&truth),
                "--landmarks".into(),
                s(&lm),
                "--make-landmarks".into(),
                set.landmarks.to_string(),
                "--landmark-range-m".into(),
                set.landmark_range_m.0.to_string(),
                set.landmark_range_m.1.to_string(),
                "--max-range-m".into(),
                set.max_range_m.to_string(),
                "--sigma-m".into(),
                "1".into(),
                "--period-s".into(),
                "1".into(),
                "--seed".into(),
                REAL_SEED.to_string(),
                "--out".into(),
                s(&sightings),
            ],
        )?;
        for (filter, preset) in [
            ("none", "mems"),
            ("kf", "mems"),
            ("akf", "mems"),
            ("kf", "paper"),
            ("akf", "paper"),
        ] {
            let tag = format!("{}_{filter}_{preset}", set.name);
            let json = out.join(format!("{tag}.json"));
            let mut a: Vec<String> = vec![
                "ins".into(),
                "--imu".into(),
                s(&imu),
                "--truth".into(),
                s(&truth),
                "--filter".into(),
                filter.into(),
                "--preset".into(),
                preset.into(),
                "--align-s".into(),
                set.align_s.to_string(),
                "--rate".into(),
                "10".into(),
                "--out".into(),
                s(&out.join(format!("{tag}.csv"))),
                "--metrics-json".into(),
                s(&json),
            ];
            if let Some(t) = set.start_s {
                a.extend(["--start-s".into(), t.to_string()]);
            }
            if filter != "none" {
                a.extend([
                    "--sightings".into(),
                    s(&sightings),
                    "--landmarks".into(),
                    s(&lm),
                ]);
            }
            if (filter, preset) == ("kf", "mems") {
                a.extend(["--plot".into(), s(&out.join(format!("{tag}.png")))]);
            }
            let _ = std::fs::remove_file(&json);
            let row = match nav_app(&exe, &a) {
                Ok(()) => {
                    let text = std::fs::read_to_string(&json)
                        .with_context(|| format!("reading {}", json.display()))?;
                    let v: serde_json::Value = serde_json::from_str(&text)?;
                    let m = &v["metrics"];
                    format!(
                        "| {} | {filter} | {preset} | {} / {} | {} | {} | {} / {} / {} | {} | {} |\n",
                        set.name,
                        fmt_cell(m, &["position_m", "rms"], 1.0, 2),
                        fmt_cell(m, &["position_m", "max"], 1.0, 2),
                        fmt_cell(m, &["velocity_mps", "rms"], 1.0, 2),
                        fmt_cell(m, &["attitude_rad", "rms"], 1e3, 1),
                        fmt_cell(m, &["position_m", "inside_2sigma_epochs"], 100.0, 0),
                        fmt_cell(m, &["velocity_mps", "inside_2sigma_epochs"], 100.0, 0),
                        fmt_cell(m, &["attitude_rad", "inside_2sigma_epochs"], 100.0, 0),
                        fmt_cell(m, &["nis_per_dof"], 1.0, 2),
                        fmt_cell(m, &["nees_per_dof"], 1.0, 2),
                    )
                }
                Err(e) => {
                    let first = e.to_string();
                    let why = first.lines().last().unwrap_or("failed").trim().to_owned();
                    format!(
                        "| {} | {filter} | {preset} | diverged: {why} | | | | | |\n",
                        set.name
                    )
                }
            };
            print!("{row}");
            md.push_str(&row);
        }
    }
    if ran == 0 {
        bail!("ins-real: no real IMU log under {}", data.display());
    }
    let mut doc = String::new();
    writeln!(
        doc,
        "# INS/SD on real IMU logs (`cargo xtask ins-real`)\n\nSightings σ 1 m at 1 Hz from each reference, seed {REAL_SEED}; error statistics at the reference's rows, an epoch is inside 2σ when its 3-D error lies inside the filter's 2σ ellipsoid (NEES of the block ≤ χ²₃(0.9545)); the JSON also has the per-(time, axis) fraction.\n"
    )?;
    doc.push_str(&md);
    let path = out.join("summary.md");
    std::fs::write(&path, doc).with_context(|| format!("writing {}", path.display()))?;
    eprintln!("ins-real: wrote {}", path.display());
    Ok(())
}
