//! `nav-app ins`'s options for the data sets' own layouts and trajectories out:
//! `--imu-to-body`, `--tum-origin`, `--tum-frame` (read by `ins_sim::logs`'s `asl` and `local`
//! modules) and `--tum-out`, `--tum-truth-out`.

use std::io::BufWriter;
use std::path::Path;

use anyhow::{Context, Result, bail};
use ins_sim::logs::{self, ReplaySummary};

use super::InsArgs;

/// `--tum-frame` (default enu).
pub(super) fn tum_axes(args: &InsArgs) -> Result<logs::LocalAxes> {
    logs::LocalAxes::parse(args.tum_frame.as_deref().unwrap_or("enu"))
        .context("--tum-frame: enu or ned")
}

/// `--tum-out`, `--tum-truth-out`: the solution read back from its CSV, and the reference at the
/// times the errors were computed, in one local frame.
pub(super) fn write_tum_files(
    args: &InsArgs,
    layouts: &logs::InputLayouts,
    out_path: &Path,
    reference: Option<&[logs::ReferenceRow]>,
    summary: &ReplaySummary,
) -> Result<()> {
    if args.tum_out.is_none() && args.tum_truth_out.is_none() {
        return Ok(());
    }
    let solution = logs::read_solution(out_path)?;
    let frame = match (layouts.local_frame, solution.first()) {
        (Some(frame), _) => frame,
        (None, Some((_, first))) => logs::LocalFrame {
            origin: first.pos,
            axes: tum_axes(args)?,
        },
        (None, None) => bail!("--tum-out: the solution {} has no row", out_path.display()),
    };
    let create = |path: &Path| -> Result<BufWriter<std::fs::File>> {
        Ok(BufWriter::new(
            std::fs::File::create(path).with_context(|| format!("creating {}", path.display()))?,
        ))
    };
    if let Some(path) = &args.tum_out {
        let rows = solution.iter().map(|(t, s)| (*t, s.pos, s.att_b_to_n));
        logs::write_tum(
            &mut create(path)?,
            path,
            &frame,
            "nav-app ins solution",
            rows,
        )?;
    }
    if let (Some(path), Some(rows), Some(m)) = (&args.tum_truth_out, reference, &summary.metrics) {
        // The reference interpolated at each compared time exactly as the metrics did (the
        // same function and gap), so a trajectory tool's RMS over these rows is the printed one.
        let has_attitude = rows.iter().all(|r| r.att_b_to_n.is_some());
        let mut cursor = 0;
        let poses = m.series.iter().filter_map(|e| {
            logs::interpolate(rows, e.t_s, logs::METRICS_MAX_REFERENCE_GAP_S, &mut cursor)
                .map(|r| (e.t_s, r.pos, r.att_b_to_n.unwrap_or_default()))
        });
        let what = if has_attitude {
            "nav-app ins reference at the compared times"
        } else {
            "nav-app ins reference at the compared times (no attitude in the reference: identity quaternions, compare positions only)"
        };
        logs::write_tum(&mut create(path)?, path, &frame, what, poses)?;
    }
    Ok(())
}

/// `--imu-to-body R11,…,R33` (row-major), checked to be a rotation.
pub(super) fn parse_rotation(text: Option<&str>) -> Result<Option<nalgebra::Matrix3<f64>>> {
    Ok(match text {
        Some(text) => {
            let v: Vec<f64> = text
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .ok()
                .filter(|v: &Vec<f64>| v.len() == 9)
                .with_context(|| {
                    format!("--imu-to-body: `{text}` is not 9 numbers R11,R12,…,R33 (row-major)")
                })?;
            Some(logs::check_rotation(
                nalgebra::Matrix3::from_row_slice(&v),
                "--imu-to-body",
            )?)
        }
        None => None,
    })
}

/// `--imu-to-body`, `--tum-origin`, `--tum-frame`.
pub(super) fn input_layouts(args: &InsArgs) -> Result<logs::InputLayouts> {
    let imu_to_body = parse_rotation(args.imu_to_body.as_deref())?;
    let local_frame = match (&args.tum_origin, &args.tum_frame) {
        (Some(origin), Some(_)) => Some(logs::LocalFrame::from_text(origin, tum_axes(args)?)?),
        (Some(_), None) => {
            bail!("--tum-origin: give the local frame's axes too, --tum-frame enu|ned")
        }
        _ => None,
    };
    let local_truth = match &args.truth {
        Some(path) => logs::is_local_reference(path)?,
        None => false,
    };
    if (args.tum_origin.is_some() || args.tum_frame.is_some())
        && !local_truth
        && args.tum_out.is_none()
        && args.tum_truth_out.is_none()
    {
        bail!(
            "--tum-origin, --tum-frame: the local frame of a TUM or ASL reference (--truth) or of \
             --tum-out; neither is given"
        );
    }
    Ok(logs::InputLayouts {
        imu_to_body,
        local_frame,
    })
}
