//! The INS/SD half from Python: the online filter object (`ins-sd-filter`, the same code the Monte
//! Carlo and `nav-app ins` run), log export of a simulated flight, and one simulated flight as
//! numpy time series.

use std::path::Path;

use nalgebra::Vector3;
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use ins_errors::strapdown::NavState;
use ins_sim::filter_file::FilterFile;
use ins_sim::{Mode, Sample, Scenario, logs};

use crate::NavError;

use crate::nav_err as err;

/// A [`NavError`] with a message of this module's own (a file it could not read or create).
fn message(text: String) -> PyErr {
    NavError::new_err(text)
}

/// `None` → the paper's scenario (`configs/paper.toml`, built in); else a scenario TOML path.
fn load_scenario(config: Option<&str>) -> PyResult<Scenario> {
    match config {
        None => Ok(Scenario::paper_default()),
        Some(path) => {
            let text =
                std::fs::read_to_string(path).map_err(|e| message(format!("{path}: {e}")))?;
            Scenario::from_toml_named(path, &text).map_err(err)
        }
    }
}

fn report_dict<'py>(
    py: Python<'py>,
    r: &ins_sd_filter::UpdateReport,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("used", r.used)?;
    d.set_item("rejected", r.rejected)?;
    d.set_item("nis", r.nis)?;
    d.set_item("adaptive_q", r.adaptive_q)?;
    d.set_item("fed_back", r.fed_back)?;
    Ok(d)
}

/// A filter file by path, or a compiled-in preset by name (`mems` when neither is given).
fn load_filter_file(path: Option<&str>, preset: Option<&str>) -> PyResult<FilterFile> {
    match (path, preset) {
        (Some(_), Some(_)) => Err(PyValueError::new_err(
            "give filter_file or preset, not both",
        )),
        (Some(path), None) => {
            let text =
                std::fs::read_to_string(path).map_err(|e| message(format!("{path}: {e}")))?;
            FilterFile::from_toml_str(&text, path).map_err(err)
        }
        (None, name) => FilterFile::preset(name.unwrap_or("mems")).map_err(err),
    }
}

fn mode_of(filter: &str) -> PyResult<Mode> {
    Ok(match filter {
        "standalone" | "none" => Mode::Standalone,
        "kf" => Mode::Kf,
        "akf" => Mode::Akf,
        "akf_sage_husa" => Mode::AkfSageHusa,
        "akf_structured" => Mode::AkfStructured,
        other => {
            return Err(PyValueError::new_err(format!(
                "filter must be one of none (standalone), kf, akf, akf_sage_husa, akf_structured; not {other:?}"
            )));
        }
    })
}

fn vec3(name: &str, v: &[f64]) -> PyResult<Vector3<f64>> {
    match v {
        [x, y, z] => Ok(Vector3::new(*x, *y, *z)),
        _ => Err(PyValueError::new_err(format!(
            "{name} must have 3 components, got {}",
            v.len()
        ))),
    }
}

fn nav_dict<'py>(py: Python<'py>, s: &NavState) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("lat_rad", s.pos.lat_rad)?;
    d.set_item("lon_rad", s.pos.lon_rad)?;
    d.set_item("alt_m", s.pos.alt_m)?;
    d.set_item(
        "vel_ned_mps",
        (s.vel_ned_mps[0], s.vel_ned_mps[1], s.vel_ned_mps[2]),
    )?;
    let q = s.att_b_to_n.quaternion();
    d.set_item("att_quat_wxyz", (q.w, q.i, q.j, q.k))?;
    Ok(d)
}

/// The online INS/SD filter: `InsSdFilter(landmarks, initial, config=None, filter="kf",
/// gate=None)` with a landmark table and an initial state in the TOML formats of
/// `ins_sim::logs` (what `export_run` writes), the filter settings of a scenario file
/// (`None`: the paper's), `filter` `"kf"` or `"akf"`, and an optional χ² gate probability per
/// sighting.
#[pyclass(module = "ita_nav")]
pub struct InsSdFilter {
    inner: ins_sd_filter::InsSdFilter,
    sightings: Vec<ins_sd_filter::Sighting>,
    pointed: Vec<ins_sd_filter::PointedSighting>,
}

#[pymethods]
impl InsSdFilter {
    #[new]
    #[pyo3(signature = (landmarks, initial, config=None, filter="kf", gate=None, filter_file=None, preset=None, imu_step_s=0.01))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        landmarks: &str,
        initial: &str,
        config: Option<&str>,
        filter: &str,
        gate: Option<f64>,
        filter_file: Option<&str>,
        preset: Option<&str>,
        imu_step_s: f64,
    ) -> PyResult<Self> {
        let mode = mode_of(filter)?;
        let table = logs::read_landmarks(Path::new(landmarks)).map_err(err)?;
        let init = logs::read_initial(Path::new(initial)).map_err(err)?;
        let mut cfg = match (filter_file, preset) {
            (None, None) => load_scenario(config)?.online_filter_config(mode),
            (file, name) => {
                if config.is_some() {
                    return Err(PyValueError::new_err(
                        "give either config (a scenario) or filter_file / preset, not both",
                    ));
                }
                load_filter_file(file, name)?
                    .filter_config(mode, imu_step_s, init.t_s)
                    .map_err(err)?
            }
        };
        cfg.gate_probability = gate;
        let inner = ins_sd_filter::InsSdFilter::new(cfg, table, init.nav_state(), init.t_s)
            .map_err(|e| message(format!("{initial}: {e}")))?;
        Ok(InsSdFilter {
            inner,
            sightings: Vec::new(),
            pointed: Vec::new(),
        })
    }

    /// One IMU sample ending at `t_s` (s) as mean rates over it: `specific_force_body_mps2` and
    /// `ang_rate_body_radps` (3 components each, body FRD). Raises `NavError` as `propagate`.
    fn propagate_rates(
        &mut self,
        t_s: f64,
        specific_force_body_mps2: Vec<f64>,
        ang_rate_body_radps: Vec<f64>,
    ) -> PyResult<()> {
        let f = vec3("specific_force_body_mps2", &specific_force_body_mps2)?;
        let w = vec3("ang_rate_body_radps", &ang_rate_body_radps)?;
        self.inner.propagate_rates(t_s, &f, &w).map_err(err)
    }

    /// Sightings that carry their pointing at epoch `t_s`: `(landmark_id, frame, x, y, z)` with
    /// `frame` `"body"` or `"ned"` and (x, y, z) the measured line of sight (format 2 of
    /// `sightings.csv`). Returns what `update` returns; a direction behind the camera counts as
    /// rejected.
    fn update_pointed<'py>(
        &mut self,
        py: Python<'py>,
        t_s: f64,
        sightings: Vec<(u32, String, f64, f64, f64)>,
    ) -> PyResult<Bound<'py, PyDict>> {
        self.pointed.clear();
        for (id, frame, x, y, z) in sightings {
            let frame = ins_sd_filter::LosFrame::parse(&frame).ok_or_else(|| {
                PyValueError::new_err(format!("frame must be \"body\" or \"ned\", not {frame:?}"))
            })?;
            self.pointed.push(ins_sd_filter::PointedSighting {
                landmark_id: id,
                frame,
                los: Vector3::new(x, y, z),
            });
        }
        let r = self.inner.update_pointed(t_s, &self.pointed).map_err(err)?;
        report_dict(py, &r)
    }

    /// One IMU sample ending at `t_s` (s): `dv_body_mps` = ∫ f̃ dt and `dtheta_body_rad` = ∫ ω̃ dt
    /// over the sample (3 components each, body FRD). Raises `NavError` for out-of-order time
    /// or non-finite input.
    fn propagate(
        &mut self,
        t_s: f64,
        dv_body_mps: Vec<f64>,
        dtheta_body_rad: Vec<f64>,
    ) -> PyResult<()> {
        let dv = vec3("dv_body_mps", &dv_body_mps)?;
        let dth = vec3("dtheta_body_rad", &dtheta_body_rad)?;
        self.inner.propagate(t_s, &dv, &dth).map_err(err)
    }

    /// Sightings at epoch `t_s` (the INS time): `(landmark_id, w_m, h_m)` tuples, 0 to many.
    /// Returns `{"used", "rejected", "nis", "adaptive_q", "fed_back"}`. Raises `NavError` for an
    /// unknown landmark, a time off the INS time, or non-finite input (nothing changes then).
    fn update<'py>(
        &mut self,
        py: Python<'py>,
        t_s: f64,
        sightings: Vec<(u32, f64, f64)>,
    ) -> PyResult<Bound<'py, PyDict>> {
        self.sightings.clear();
        self.sightings.extend(
            sightings
                .into_iter()
                .map(|(id, w, h)| ins_sd_filter::Sighting {
                    landmark_id: id,
                    w_m: w,
                    h_m: h,
                }),
        );
        let r = self.inner.update(t_s, &self.sightings).map_err(err)?;
        report_dict(py, &r)
    }

    /// Time of the INS, s.
    #[getter]
    fn time_s(&self) -> f64 {
        self.inner.time_s()
    }

    /// The 15 error states (δp m NED, δv m/s, ψ rad, ∇ m/s², ε rad/s), computed − true.
    #[getter]
    fn error_state<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.inner.error_state().as_slice())
    }

    /// The 15×15 error covariance (`None` for no estimator).
    #[getter]
    fn covariance<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
        let Some(p) = self.inner.covariance() else {
            return Ok(None);
        };
        let rows: Vec<Vec<f64>> = (0..15)
            .map(|i| (0..15).map(|j| p[(i, j)]).collect())
            .collect();
        Ok(Some(PyArray2::from_vec2(py, &rows)?))
    }

    /// The corrected navigation solution: `lat_rad`, `lon_rad`, `alt_m`, `vel_ned_mps`,
    /// `att_quat_wxyz` (body FRD → NED).
    fn navigation<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        nav_dict(py, &self.inner.navigation_solution())
    }

    /// Totals: `imu_samples`, `epochs`, `sightings_used`, `sightings_rejected`, `adaptive_q_used`.
    #[getter]
    fn statistics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.inner.statistics();
        let d = PyDict::new(py);
        d.set_item("imu_samples", s.imu_samples)?;
        d.set_item("epochs", s.epochs)?;
        d.set_item("sightings_used", s.sightings_used)?;
        d.set_item("sightings_rejected", s.sightings_rejected)?;
        d.set_item("adaptive_q_used", s.adaptive_q_used)?;
        Ok(d)
    }
}

/// Simulate run `seed` of a scenario (`config=None`: the paper's) with `filter` and write its logs
/// into `out_dir` (imu.csv, sightings.csv, truth.csv, landmarks.toml, initial.toml, scenario.toml
/// and the simulated filter's solution.csv) — the files `InsSdFilter` and `nav-app ins` replay.
#[pyfunction]
#[pyo3(signature = (out_dir, config=None, filter="kf", seed=0))]
pub fn export_run(out_dir: &str, config: Option<&str>, filter: &str, seed: u64) -> PyResult<usize> {
    let scenario = load_scenario(config)?;
    std::fs::create_dir_all(out_dir).map_err(|e| message(format!("{out_dir}: {e}")))?;
    let (outcome, _) =
        logs::export_run(&scenario, mode_of(filter)?, seed, Path::new(out_dir)).map_err(err)?;
    Ok(outcome.samples_written)
}

/// One simulated flight (`config=None`: the paper's scenario; `filter` one of standalone, kf, akf,
/// akf_sage_husa, akf_structured; `seed` the run's seed) as numpy arrays at the record rate:
/// `t_s` (n), `pos_err_ned_m` (n×3), `vel_err_ned_mps` (n×3), `misalignment_rad` (n×3),
/// `distance_m` (n), `nees` and `nis` (n, NaN off the sighting epochs).
#[pyfunction]
#[pyo3(signature = (config=None, filter="kf", seed=0))]
pub fn run_flight<'py>(
    py: Python<'py>,
    config: Option<&str>,
    filter: &str,
    seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let scenario = load_scenario(config)?;
    let mode = mode_of(filter)?;
    let mut out = vec![Sample::default(); scenario.samples_per_run()];
    let outcome = py
        .detach(|| ins_sim::run(&scenario, mode, seed, &mut out))
        .map_err(err)?;
    out.truncate(outcome.samples_written);
    let col3 = |f: fn(&Sample) -> [f64; 3]| -> Vec<Vec<f64>> {
        out.iter().map(|s| f(s).to_vec()).collect()
    };
    let d = PyDict::new(py);
    d.set_item(
        "t_s",
        PyArray1::from_vec(py, out.iter().map(|s| s.t_s).collect()),
    )?;
    d.set_item(
        "pos_err_ned_m",
        PyArray2::from_vec2(py, &col3(|s| s.pos_err_ned_m))?,
    )?;
    d.set_item(
        "vel_err_ned_mps",
        PyArray2::from_vec2(py, &col3(|s| s.vel_err_ned_mps))?,
    )?;
    d.set_item(
        "misalignment_rad",
        PyArray2::from_vec2(py, &col3(|s| s.misalignment_rad))?,
    )?;
    d.set_item(
        "distance_m",
        PyArray1::from_vec(py, out.iter().map(|s| s.distance_m).collect()),
    )?;
    for (k, f) in [
        ("nees", (|s: &Sample| s.nees) as fn(&Sample) -> Option<f64>),
        ("nis", |s: &Sample| s.nis),
    ] {
        d.set_item(
            k,
            PyArray1::from_vec(py, out.iter().map(|s| f(s).unwrap_or(f64::NAN)).collect()),
        )?;
    }
    Ok(d)
}

/// The Monte Carlo of the paper (or of any scenario): `runs` flights per filter (default: the
/// scenario's), run `i` seeded with `run_seed(seed, i)` exactly as `cargo xtask monte-carlo`
/// does (so the same runs, through the same run loop `ins_sim::runs::run_range` and its exclusion
/// rule), folded in run order by the same statistics (`ins_sim::stats`).
/// Returns `{"runs", "seed", "t_s", "modes": {name: {"runs_used", "excluded", "rms_pos_3d_m",
/// "rms_pos_h_m", "rms_pos_d_m", "mean_nees", "mean_nis", "final_rms_pos_3d_m",
/// "final_rms_pos_h_m", "final_rms_pos_d_m", "final_pos_3d_m"}}}` with the per-second series as numpy
/// arrays (NaN where undefined) and `final_pos_3d_m` the kept runs' final 3-D errors.
/// Single-threaded; the GIL is released while it runs.
#[pyfunction]
#[pyo3(signature = (config=None, runs=None, seed=None, filters=None))]
pub fn monte_carlo<'py>(
    py: Python<'py>,
    config: Option<&str>,
    runs: Option<u64>,
    seed: Option<u64>,
    filters: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyDict>> {
    use ins_sim::runs::{closed_loop, run_range};
    use ins_sim::stats::{Exclusion, ModeStats, RunSummary, qi};
    let scenario = load_scenario(config)?;
    let runs = runs.unwrap_or(scenario.monte_carlo.runs as u64);
    let seed = seed.unwrap_or(scenario.monte_carlo.seed);
    let names = filters.unwrap_or_else(|| vec!["standalone".into(), "kf".into(), "akf".into()]);
    let modes: Vec<Mode> = names.iter().map(|n| mode_of(n)).collect::<PyResult<_>>()?;
    let n = scenario.samples_per_run();
    type Folded = (ModeStats, Vec<RunSummary>, Vec<Exclusion>);
    // The one Monte Carlo run loop (`ins_sim::runs::run_range`): the same seeds and the same
    // exclusion rule as the Monte Carlo driver.
    let folded: Vec<Folded> = py
        .detach(|| {
            let runner = closed_loop(&scenario, seed);
            let mut out = vec![Sample::default(); n];
            modes
                .iter()
                .map(|&mode| {
                    let mut st = ModeStats::new(mode, n);
                    let (mut kept, mut excluded) = (Vec::new(), Vec::new());
                    run_range(&runner, mode, 0..runs, &mut out, |i, out, verdict| {
                        verdict.fold(i, out, &mut st, &mut kept, &mut excluded);
                    })?;
                    Ok((st, kept, excluded))
                })
                .collect::<Result<Vec<_>, ins_sim::SimError>>()
        })
        .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("runs", runs)?;
    d.set_item("seed", seed)?;
    d.set_item(
        "t_s",
        PyArray1::from_vec(
            py,
            (0..n)
                .map(|k| k as f64 * scenario.duration_s() / (n - 1).max(1) as f64)
                .collect(),
        ),
    )?;
    let per_mode = PyDict::new(py);
    for (name, (st, kept, excluded)) in names.iter().zip(&folded) {
        let m = PyDict::new(py);
        m.set_item("runs_used", st.runs_used)?;
        let ex: Vec<Bound<'py, PyDict>> = excluded
            .iter()
            .map(|x| {
                let e = PyDict::new(py);
                e.set_item("run_index", x.run_index)?;
                e.set_item("t_s", x.t_s.unwrap_or(f64::NAN))?;
                e.set_item("reason", &x.reason)?;
                Ok(e)
            })
            .collect::<PyResult<_>>()?;
        m.set_item("excluded", ex)?;
        let series = |q: usize, mean: bool| -> Vec<f64> {
            st.bins
                .iter()
                .map(|b| if mean { b[q].mean() } else { b[q].rms() })
                .collect()
        };
        for (key, q, mean) in [
            ("rms_pos_3d_m", qi::POS_3D, false),
            ("rms_pos_h_m", qi::POS_H, false),
            ("rms_pos_d_m", qi::POS_D, false),
            ("mean_nees", qi::NEES, true),
            ("mean_nis", qi::NIS, true),
        ] {
            let v = series(q, mean);
            if let Some(last) = v.last().copied().filter(|_| !mean) {
                m.set_item(format!("final_{key}"), last)?;
            }
            m.set_item(key, PyArray1::from_vec(py, v))?;
        }
        m.set_item(
            "final_pos_3d_m",
            PyArray1::from_vec(py, kept.iter().map(|r| r.final_pos_3d_m).collect()),
        )?;
        per_mode.set_item(name, m)?;
    }
    d.set_item("modes", per_mode)?;
    Ok(d)
}

/// Replay an IMU log (CSV increments or rates, or a ROS 2 bag's `imu_topic`) through the filter, as `nav-app ins` does: sightings
/// (with `landmarks`) or unaided (`filter="none"`), the initial state from `initial` or from the
/// reference `truth` at `start_s`, the filter settings from `filter_file` or `preset` (default
/// mems), an optional static alignment `align_s`, solution rows into `out` at `rate_hz` (None:
/// every sample); a filter that used no sighting is refused unless `allow_unaided`. Returns the
/// summary, and with `truth` the metrics (`position_m`,
/// `velocity_mps`, `attitude_rad`, `nees_per_dof`, `nis_per_dof`, … as in `--metrics-json`).
#[pyfunction]
#[pyo3(signature = (imu, out, sightings=None, landmarks=None, initial=None, truth=None, start_s=None, filter="kf", filter_file=None, preset=None, gate=None, align_s=0.0, max_gap_s=5.0, rate_hz=None, imu_topic=None, allow_unaided=false))]
#[allow(clippy::too_many_arguments)]
pub fn replay<'py>(
    py: Python<'py>,
    imu: &str,
    out: &str,
    sightings: Option<&str>,
    landmarks: Option<&str>,
    initial: Option<&str>,
    truth: Option<&str>,
    start_s: Option<f64>,
    filter: &str,
    filter_file: Option<&str>,
    preset: Option<&str>,
    gate: Option<f64>,
    align_s: f64,
    max_gap_s: f64,
    rate_hz: Option<f64>,
    imu_topic: Option<&str>,
    allow_unaided: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let request = logs::ReplayRequest {
        imu: imu.into(),
        imu_topic: imu_topic.map(Into::into),
        sightings: sightings.map(Into::into).zip(landmarks.map(Into::into)),
        initial: initial.map(Into::into),
        reference: truth.map(Into::into),
        start_s,
        settings: logs::FilterSettings::File(load_filter_file(filter_file, preset)?),
        mode: mode_of(filter)?,
        gate: gate.map(|p| (p != 0.0).then_some(p)),
        align_s,
        allow_unaided,
        max_gap_s,
        rate: rate_hz.map_or(logs::SolutionRate::EveryImu, logs::SolutionRate::Hz),
        mcap_out: None,
        layouts: Default::default(),
    };
    let inputs = request.inputs().map_err(err)?;
    let summary = py
        .detach(move || -> Result<logs::ReplaySummary, String> {
            let file = std::fs::File::create(out).map_err(|e| format!("{out}: {e}"))?;
            let mut w = std::io::BufWriter::new(file);
            logs::replay(inputs, &mut w, Path::new(out)).map_err(|e| crate::error_text(&e))
        })
        .map_err(message)?;
    let d = PyDict::new(py);
    d.set_item("imu_samples", summary.imu_samples)?;
    d.set_item("epochs", summary.epochs)?;
    d.set_item("sightings_used", summary.sightings_used)?;
    d.set_item("sightings_rejected", summary.sightings_rejected)?;
    d.set_item("lead_in_s", summary.lead_in_s)?;
    d.set_item("gaps", summary.gaps)?;
    d.set_item("longest_gap_s", summary.longest_gap_s)?;
    d.set_item("end_t_s", summary.end_t_s)?;
    if let Some(m) = &summary.metrics {
        let json = serde_json::to_string(m).map_err(err)?;
        let json_mod = py.import("json")?;
        d.set_item("metrics", json_mod.call_method1("loads", (json,))?)?;
    }
    Ok(d)
}

/// Write a pointed-sightings log from a reference trajectory (`nav-app ins sightings`): with
/// `make_landmarks=N`, first place N landmarks around it (`landmark_range_m`, seeded) and write
/// them to `landmarks`. Returns `{"epochs", "sightings", "min_per_epoch", "empty_epochs",
/// "frame"}`.
#[pyfunction]
#[pyo3(signature = (reference, landmarks, out, sigma_m=1.0, period_s=1.0, max_range_m=1000.0, max_per_epoch=6, field_of_regard_deg=180.0, make_landmarks=None, landmark_range_m=(50.0, 300.0), seed=1))]
#[allow(clippy::too_many_arguments)]
pub fn write_sightings<'py>(
    py: Python<'py>,
    reference: &str,
    landmarks: &str,
    out: &str,
    sigma_m: f64,
    period_s: f64,
    max_range_m: f64,
    max_per_epoch: usize,
    field_of_regard_deg: f64,
    make_landmarks: Option<usize>,
    landmark_range_m: (f64, f64),
    seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let rows = logs::read_reference(Path::new(reference)).map_err(err)?;
    if let Some(n) = make_landmarks {
        let entries =
            logs::landmarks_around(&rows, n, landmark_range_m.0, landmark_range_m.1, seed)
                .map_err(err)?;
        logs::write_landmarks(Path::new(landmarks), &entries).map_err(err)?;
    }
    let table = logs::read_landmarks(Path::new(landmarks)).map_err(err)?;
    let plan = logs::SightingPlan {
        sigma_m,
        period_s,
        max_range_m,
        max_per_epoch,
        field_of_regard_deg,
        seed,
        ..logs::SightingPlan::default()
    };
    let file = std::fs::File::create(out).map_err(|e| message(format!("{out}: {e}")))?;
    let w = logs::write_sightings(
        &rows,
        &table,
        &plan,
        &mut std::io::BufWriter::new(file),
        Path::new(out),
    )
    .map_err(err)?;
    let d = PyDict::new(py);
    d.set_item("epochs", w.epochs)?;
    d.set_item("sightings", w.sightings)?;
    d.set_item("min_per_epoch", w.min_per_epoch)?;
    d.set_item("empty_epochs", w.empty_epochs)?;
    d.set_item("frame", if w.frame_is_body { "body" } else { "ned" })?;
    Ok(d)
}
