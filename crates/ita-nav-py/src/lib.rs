//! # ita_nav — the lane tracker and the INS/SD filter from Python
//!
//! A Python extension module (PyO3, built by maturin) over the library crates, not over the binary:
//! [`lane_tracker::LaneTracker`] (directional gradient → Hough + least squares → Kalman information
//! filter, the lane paper's Fig. 1) on numpy frames, with the lane covariance and, given a camera,
//! the ego lane in metres; and (module `ins`) the online INS/SD filter `InsSdFilter`
//! (`ins-sd-filter`), `export_run`, `run_flight` and `monte_carlo` (the same runs and statistics,
//! `ins_sim::stats`, as `cargo xtask monte-carlo`).
//!
//! ```python
//! import numpy as np, ita_nav
//! tracker = ita_nav.LaneTracker()              # the default configuration (configs/default.toml)
//! lanes = tracker.track(frame)                 # frame: uint8 H×W (grey) or H×W×3 (RGB)
//! left, right = lanes
//! left["coeffs"]                               # (a1, a2, a3) of x = a1·y² + a2·y + a3, px; or None
//! ```
//!
//! ## Frames
//! A C-contiguous `uint8` array `H×W` is read in place (no copy): the tracker borrows numpy's
//! buffer for the duration of the call. An `H×W×3` array is taken as R'G'B' and converted to grey
//! with BT.601 luma, `Y' = 0.299 R' + 0.587 G' + 0.114 B'` (the same conversion as capture,
//! `bt848_capture::convert::luma_bt601`), into a buffer the tracker keeps. Another dtype or number
//! of dimensions raises `TypeError`; a non-contiguous array or a frame of another size than the
//! first one raises `ValueError`; configuration and tracking errors raise `ita_nav.NavError`.
//!
//! ## Lanes
//! `track` returns `[left, right]`, each a dict: `side` (`"left"`/`"right"`), `state`
//! (`"initialising"`, `"tracking"`, `"coasting"`, `"lost"`), `coeffs` (`(a1, a2, a3)` in the input's
//! pixels, or `None`), `rows` (`(y_min, y_max)` px of the points behind the estimate), `points`
//! (used this frame), `initialised` (Hough + LS ran for it on this frame), `covariance` (3×3
//! numpy array: covariance of `coeffs` in pixels, from the KIF's information matrix; `None`
//! without an estimate). With a camera (`LaneTracker(camera="robot")`), `tracker.ego_lane` gives
//! the lane in metres with σ after each frame (`lane-geometry`).

use std::time::Instant;

mod ins;

use numpy::{PyArrayMethods, PyReadonlyArray2, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::exceptions::{PyException, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use lane_tracker::camera::CameraModel;
use lane_tracker::{Estimator, LaneReport, LaneTracker as RustTracker, Side};

pyo3::create_exception!(
    ita_nav,
    NavError,
    PyException,
    "A configuration, frame or tracking error from the Rust library (the message names the field, file or frame)."
);

/// A [`NavError`] whose message is `e` and its causes, `e: cause: cause's cause…` (each error of
/// the Rust library displays only its own message and keeps its cause as its source).
fn nav_err(e: impl std::error::Error + 'static) -> PyErr {
    NavError::new_err(error_text(&e))
}

/// `e` and its causes as one line, following [`std::error::Error::source`].
fn error_text(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut next = e.source();
    while let Some(cause) = next {
        text.push_str(": ");
        text.push_str(&cause.to_string());
        next = cause.source();
    }
    text
}

/// The lane tracker (one per video stream). Frames must keep the size of the first one.
#[pyclass(module = "ita_nav")]
struct LaneTracker {
    config: lane_tracker::TrackerConfig,
    estimator: Estimator,
    camera: Option<CameraModel>,
    tracker: Option<RustTracker>,
    grey: Vec<u8>,
    last_track_us: f64,
    last_ego: Option<lane_tracker::camera::EgoLaneReport>,
}

impl LaneTracker {
    fn tracker_for(&mut self, width: usize, height: usize) -> PyResult<&mut RustTracker> {
        if let Some(t) = &self.tracker {
            let (w, h) = t.frame_size();
            if (w, h) != (width, height) {
                return Err(PyValueError::new_err(format!(
                    "frame is {height}×{width} (H×W), this tracker takes {h}×{w}; \
                     use a new LaneTracker for another frame size"
                )));
            }
        }
        if let Some(c) = &self.camera {
            c.check_frame_size(width, height).map_err(nav_err)?;
        }
        let slot = &mut self.tracker;
        match slot {
            Some(t) => Ok(t),
            None => Ok(slot.insert(
                RustTracker::new(&self.config, self.estimator, width, height).map_err(nav_err)?,
            )),
        }
    }

    fn run(
        &mut self,
        data: Option<&[u8]>,
        width: usize,
        height: usize,
    ) -> PyResult<lane_tracker::TrackReport> {
        // Split borrows: the grey buffer and the tracker are separate fields.
        self.tracker_for(width, height)?;
        let LaneTracker {
            tracker,
            grey,
            last_track_us,
            ..
        } = self;
        let t = tracker
            .as_mut()
            .ok_or_else(|| PyValueError::new_err("no tracker"))?;
        let pixels = data.unwrap_or(grey.as_slice());
        let t0 = Instant::now();
        let report = t
            .track_pixels(pixels, width, height, width)
            .map_err(nav_err)?;
        *last_track_us = t0.elapsed().as_secs_f64() * 1e6;
        Ok(report)
    }
}

/// The array's pixels in row-major order, borrowed: only a C-contiguous array qualifies (numpy's
/// `as_slice` also accepts a Fortran-ordered one, whose memory is the transposed image).
fn c_contiguous_slice<'a, D: numpy::ndarray::Dimension>(
    a: &'a numpy::PyReadonlyArray<'_, u8, D>,
) -> PyResult<&'a [u8]> {
    let refused =
        || PyValueError::new_err("frame is not C-contiguous: pass numpy.ascontiguousarray(frame)");
    if !a.is_c_contiguous() {
        return Err(refused());
    }
    a.as_slice().map_err(|_| refused())
}

fn lane_dict<'py>(py: Python<'py>, l: &LaneReport) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item(
        "side",
        match l.side {
            lane_tracker::Side::Left => "left",
            lane_tracker::Side::Right => "right",
        },
    )?;
    d.set_item("state", l.state.name())?;
    d.set_item("coeffs", l.coeffs.map(|[a, b, c]| (a, b, c)))?;
    d.set_item("rows", (l.rows[0], l.rows[1]))?;
    d.set_item("points", l.points)?;
    d.set_item("initialised", l.initialised)?;
    d.set_item(
        "far",
        l.far.map(|f| {
            let [a, b, c] = f.coeffs;
            ((a, b, c), (f.rows[0], f.rows[1]))
        }),
    )?;
    Ok(d)
}

#[pymethods]
impl LaneTracker {
    /// `LaneTracker(config=None, estimator="kif", camera=None)`: `config` is `None` (the default
    /// configuration), a preset name (`"default"`, `"outdoor"`, `"indoor"`) or a TOML file path;
    /// `estimator` is `"kif"` (Kalman information filter) or `"wrls"`; `camera` a camera preset
    /// (`"robot"`, `"highway"`) or file (`nav-app --camera`): with it, [`Self::ego_lane`] gives
    /// the lane in metres after every frame.
    #[new]
    #[pyo3(signature = (config=None, estimator="kif", camera=None))]
    fn new(config: Option<&str>, estimator: &str, camera: Option<&str>) -> PyResult<Self> {
        let config =
            lane_io::config::load_tracker_config(config.unwrap_or("default")).map_err(nav_err)?;
        let camera = match camera {
            Some(c) => Some(
                lane_io::config::load_camera_config(c)
                    .and_then(|c| Ok(c.model()?))
                    .map_err(nav_err)?,
            ),
            None => None,
        };
        let estimator = match estimator {
            "kif" => Estimator::Kif,
            "wrls" => Estimator::Wrls,
            other => {
                return Err(PyValueError::new_err(format!(
                    "estimator must be \"kif\" or \"wrls\", not {other:?}"
                )));
            }
        };
        Ok(LaneTracker {
            config,
            estimator,
            camera,
            tracker: None,
            grey: Vec::new(),
            last_track_us: f64::NAN,
            last_ego: None,
        })
    }

    /// Track one frame (`uint8`, H×W grey or H×W×3 RGB); returns `[left, right]` lane dicts.
    fn track<'py>(
        &mut self,
        py: Python<'py>,
        frame: &Bound<'py, PyAny>,
    ) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let report = if let Ok(a) = frame.extract::<PyReadonlyArray2<'py, u8>>() {
            let (h, w) = (a.shape()[0], a.shape()[1]);
            let data = c_contiguous_slice(&a)?;
            self.run(Some(data), w, h)?
        } else if let Ok(a) = frame.extract::<PyReadonlyArray3<'py, u8>>() {
            let (h, w, c) = (a.shape()[0], a.shape()[1], a.shape()[2]);
            if c != 3 {
                return Err(PyTypeError::new_err(format!(
                    "an H×W×C frame must have C = 3 (RGB), got C = {c}"
                )));
            }
            let rgb = c_contiguous_slice(&a)?;
            // Resized only when the frame size changes; one pass, no allocation per frame.
            self.grey.resize(w * h, 0);
            for (y, p) in self.grey.iter_mut().zip(rgb.chunks_exact(3)) {
                *y = bt848_capture::convert::luma_bt601(p[0], p[1], p[2]);
            }
            self.run(None, w, h)?
        } else {
            let dtype = frame
                .getattr("dtype")
                .map(|d| d.to_string())
                .unwrap_or_else(|_| frame.get_type().to_string());
            let shape = frame
                .getattr("shape")
                .map(|s| s.to_string())
                .unwrap_or_else(|_| "?".to_owned());
            return Err(PyTypeError::new_err(format!(
                "frame must be a numpy uint8 array H×W (grey) or H×W×3 (RGB), got dtype {dtype}, shape {shape}"
            )));
        };
        let t = self
            .tracker
            .as_ref()
            .ok_or_else(|| PyValueError::new_err("no tracker"))?;
        self.last_ego = self.camera.as_ref().and_then(|c| c.ego_lane(t, &report));
        let mut out = Vec::with_capacity(2);
        for (l, side) in report.lanes.iter().zip([Side::Left, Side::Right]) {
            let d = lane_dict(py, l)?;
            let cov = t.lane_covariance_px(side).map(|p| {
                let rows: Vec<Vec<f64>> = (0..3)
                    .map(|i| (0..3).map(|j| p[(i, j)]).collect())
                    .collect();
                rows
            });
            match cov {
                Some(rows) => d.set_item("covariance", numpy::PyArray2::from_vec2(py, &rows)?)?,
                None => d.set_item("covariance", py.None())?,
            }
            out.push(d);
        }
        Ok(out)
    }

    /// The ego lane in metres after the last frame (needs `camera=`), or `None` when the two lanes
    /// are not both held: a dict of `lateral_offset_m`, `heading_rad`, `curvature_per_m`,
    /// `lane_width_m` and each one's `*_sigma` (the per-frame JSON's `ego_lane`).
    #[getter]
    fn ego_lane<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(e) = self.last_ego else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        for (k, v) in [
            ("lateral_offset_m", e.lateral_offset_m),
            ("lateral_offset_m_sigma", e.lateral_offset_m_sigma),
            ("heading_rad", e.heading_rad),
            ("heading_rad_sigma", e.heading_rad_sigma),
            ("curvature_per_m", e.curvature_per_m),
            ("curvature_per_m_sigma", e.curvature_per_m_sigma),
            ("lane_width_m", e.lane_width_m),
            ("lane_width_m_sigma", e.lane_width_m_sigma),
        ] {
            d.set_item(k, v)?;
        }
        Ok(Some(d))
    }

    /// Forget both lanes: the next frame initialises again (Hough + least squares).
    fn reset(&mut self) {
        if let Some(t) = &mut self.tracker {
            t.reset();
        }
        self.last_ego = None;
    }

    /// `(height, width)` of the frames this tracker takes, or `None` before the first frame.
    #[getter]
    fn frame_shape(&self) -> Option<(usize, usize)> {
        self.tracker.as_ref().map(|t| {
            let (w, h) = t.frame_size();
            (h, w)
        })
    }

    /// Wall time of the Rust tracker alone on the last frame, µs (NaN before the first frame):
    /// `track`'s time minus this is the binding's overhead.
    #[getter]
    fn last_track_us(&self) -> f64 {
        self.last_track_us
    }

    /// Frames tracked and (re-)initialisations per lane since construction or `reset`.
    #[getter]
    fn counters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let c = self
            .tracker
            .as_ref()
            .map(|t| *t.counters())
            .unwrap_or_default();
        d.set_item("frames", c.frames)?;
        d.set_item(
            "initialisations",
            (c.initialisations[0], c.initialisations[1]),
        )?;
        d.set_item("gated_jumps", (c.gated_jumps[0], c.gated_jumps[1]))?;
        d.set_item(
            "gated_crossings",
            (c.gated_crossings[0], c.gated_crossings[1]),
        )?;
        d.set_item("gated_pairs", c.gated_pairs)?;
        d.set_item("revalidations", c.revalidations)?;
        d.set_item(
            "revalidation_switches",
            (c.revalidation_switches[0], c.revalidation_switches[1]),
        )?;
        d.set_item("set_asides", (c.set_asides[0], c.set_asides[1]))?;
        d.set_item("lane_changes", c.lane_changes)?;
        Ok(d)
    }

    fn __repr__(&self) -> String {
        format!(
            "LaneTracker(estimator={:?}, frame_shape={:?})",
            match self.estimator {
                Estimator::Kif => "kif",
                Estimator::Wrls => "wrls",
            },
            self.frame_shape()
        )
    }
}

/// Every frame of an input as a list of H×W uint8 arrays, read exactly as `nav-app --input PATH`
/// reads it: a YUV4MPEG2 file (`C mono` or 4:2:0, the Y plane), a directory of images (sorted) or
/// one still image. An unreadable input or a corrupt frame raises `NavError`.
#[pyfunction]
fn read_frames<'py>(py: Python<'py>, path: &str) -> PyResult<Vec<Bound<'py, numpy::PyArray2<u8>>>> {
    use lane_io::FrameSource;
    let mut src =
        lane_io::sources::open_input(std::path::Path::new(path), 25.0).map_err(nav_err)?;
    let mut frame = lane_tracker::GreyFrame::default();
    let mut out = Vec::new();
    while src.next_frame(&mut frame).map_err(nav_err)?.is_some() {
        let a = numpy::PyArray1::from_slice(py, frame.data());
        out.push(a.reshape([frame.height(), frame.width()])?);
    }
    Ok(out)
}

/// The Python module `ita_nav`.
#[pymodule]
fn ita_nav(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("NavError", m.py().get_type::<NavError>())?;
    m.add("DEFAULT_CONFIG_TOML", lane_tracker::DEFAULT_TOML)?;
    m.add_class::<LaneTracker>()?;
    m.add_function(wrap_pyfunction!(read_frames, m)?)?;
    m.add_class::<ins::InsSdFilter>()?;
    m.add_function(wrap_pyfunction!(ins::export_run, m)?)?;
    m.add_function(wrap_pyfunction!(ins::run_flight, m)?)?;
    m.add_function(wrap_pyfunction!(ins::replay, m)?)?;
    m.add_function(wrap_pyfunction!(ins::write_sightings, m)?)?;
    m.add_function(wrap_pyfunction!(ins::monte_carlo, m)?)?;
    Ok(())
}
