//! Lanes in metres: the camera file (`--camera FILE`) and the per-frame ego-lane geometry.
//!
//! The maths is in the `lane-geometry` crate (pinhole camera over a flat ground plane, the
//! ground-plane homography, image parabolas → lateral offset, heading, curvature and width,
//! and their covariance `J·diag(P_L, P_R)·Jᵀ`). This module loads the camera from TOML, takes
//! each lane's coefficients and pixel covariance from the tracker
//! ([`LaneTracker::lane_covariance_px`]) and reports [`EgoLaneReport`] for every frame where both
//! lanes are held (tracking or coasting).
//!
//! ## The camera file
//!
//! Either a modelled camera:
//!
//! ```toml
//! image_size_px = [320, 240]      # frames this camera takes, px (checked against the input)
//! [intrinsics]
//! focal_length_px = 300.0          # square pixels
//! principal_point_px = [159.5, 119.5]
//! [mounting]
//! height_m = 0.30                  # camera centre above the ground
//! pitch_down_rad = 0.20            # optical axis below the horizontal
//! roll_rad = 0.0                   # about the optical axis, right side down > 0
//! yaw_rad = 0.0                    # optical axis right of the vehicle's forward axis > 0
//! [lookahead]
//! near_m = 0.55                    # ground range ahead of the camera over which the lanes are
//! far_m = 1.0                      # sampled (choose it inside the tracker's ROI)
//! ```
//!
//! or a measured ground-plane homography, replacing `[intrinsics]` and `[mounting]`:
//!
//! ```toml
//! [homography]
//! image_points_px = [[u, v], [u, v], [u, v], [u, v]]     # four image points, px
//! ground_points_m = [[X, Y], [X, Y], [X, Y], [X, Y]]     # the same points on the ground, m
//! ```
//!
//! (ground frame: `X` forward, `Y` right, origin on the ground below the camera). Unknown fields
//! are refused and every out-of-range field is named.

use lane_geometry::{
    EgoLaneEstimator, FitRows, GeometryError, Homography, Intrinsics, Mounting, PinholeCamera,
};
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

use crate::{LaneTracker, Side, TrackReport, TrackerError};

/// The robot preset (`configs/camera-robot.toml`).
pub const CAMERA_ROBOT_TOML: &str = include_str!("../../../configs/camera-robot.toml");
/// The highway preset for the real udacity clip (`../shared/data/udacity`) (`configs/camera-highway.toml`).
pub const CAMERA_HIGHWAY_TOML: &str = include_str!("../../../configs/camera-highway.toml");

/// `[intrinsics]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntrinsicsConfig {
    /// Focal length, px (> 0; square pixels).
    pub focal_length_px: f64,
    /// Principal point `[column, row]`, px.
    pub principal_point_px: [f64; 2],
}

/// `[mounting]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MountingConfig {
    /// Camera centre above the ground, m (> 0).
    pub height_m: f64,
    /// Optical axis below the horizontal, rad.
    pub pitch_down_rad: f64,
    /// Rotation about the optical axis, rad, right side down > 0.
    pub roll_rad: f64,
    /// Optical axis to the right of the vehicle's forward axis, rad.
    pub yaw_rad: f64,
}

/// `[homography]`: four image↔ground point pairs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HomographyConfig {
    /// Four image points `[column, row]`, px, below the horizon.
    pub image_points_px: [[f64; 2]; 4],
    /// The same four points on the ground `[X fwd, Y right]`, m (no three collinear).
    pub ground_points_m: [[f64; 2]; 4],
}

/// `[lookahead]`: the ground range over which the lanes are sampled.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LookaheadConfig {
    /// Nearest ground distance ahead of the camera, m (> 0).
    pub near_m: f64,
    /// Farthest, m (> `near_m`).
    pub far_m: f64,
}

/// The whole camera file.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraConfig {
    /// Frame size `[width, height]` this camera model is for, px.
    pub image_size_px: [usize; 2],
    /// Modelled camera (with `mounting`; not with `homography`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intrinsics: Option<IntrinsicsConfig>,
    /// Modelled camera (with `intrinsics`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mounting: Option<MountingConfig>,
    /// Measured homography (instead of `intrinsics` + `mounting`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub homography: Option<HomographyConfig>,
    /// Look-ahead range.
    pub lookahead: LookaheadConfig,
}

fn field_error(field: &'static str, value: impl std::fmt::Display, reason: &str) -> TrackerError {
    TrackerError::ConfigField {
        field,
        value: value.to_string(),
        reason: reason.to_owned(),
    }
}

/// A `lane-geometry` error about a camera-file field: the field's dotted name, with the
/// component's error kept as the source; an error about no field of the file stays the
/// component's error.
fn geometry_field_error(e: GeometryError) -> TrackerError {
    let field = match &e {
        GeometryError::InvalidParameter { field, .. } => match *field {
            "focal_length_px" => Some("intrinsics.focal_length_px"),
            "principal_point_px[0]" | "principal_point_px[1]" => {
                Some("intrinsics.principal_point_px")
            }
            "height_m" => Some("mounting.height_m"),
            "pitch_down_rad" => Some("mounting.pitch_down_rad"),
            "roll_rad" => Some("mounting.roll_rad"),
            "yaw_rad" => Some("mounting.yaw_rad"),
            "lookahead_near_m" => Some("lookahead.near_m"),
            "lookahead_far_m" | "rows_px" => Some("lookahead.far_m"),
            _ => None,
        },
        GeometryError::BeyondHorizon { .. } => Some("lookahead.far_m"),
        GeometryError::DegenerateHomography { .. } | GeometryError::NonFinite { .. } => {
            Some("homography")
        }
        _ => None,
    };
    match field {
        Some(field) => TrackerError::ConfigGeometry { field, source: e },
        None => TrackerError::Geometry(e),
    }
}

impl CameraConfig {
    /// Parse and validate TOML text; `name` is used in errors.
    ///
    /// # Errors
    /// [`TrackerError::ConfigFile`]: syntax, an unknown or missing field, or the first field out of
    /// range, each with the file, line and column (the workspace's one TOML loader, `toml-config`).
    pub fn from_toml_str(name: &str, text: &str) -> Result<Self, TrackerError> {
        crate::config::parse_validated(name, text, Self::validate)
    }

    /// The preset `name` (`robot`, `highway`), or `None` for any other name (a file path, for
    /// `lane-io` to read).
    pub fn preset(name: &str) -> Option<Result<Self, TrackerError>> {
        match name {
            "robot" => Some(Self::from_toml_str(
                "preset camera-robot",
                CAMERA_ROBOT_TOML,
            )),
            "highway" => Some(Self::from_toml_str(
                "preset camera-highway",
                CAMERA_HIGHWAY_TOML,
            )),
            _ => None,
        }
    }

    /// Check every field; the error names the first offending one
    /// ([`TrackerError::config_field`]).
    ///
    /// # Errors
    /// [`TrackerError::ConfigField`], or [`TrackerError::ConfigGeometry`] for a value the
    /// lane geometry refuses (its error as the source).
    pub fn validate(&self) -> Result<(), TrackerError> {
        self.model().map(|_| ())
    }

    /// The validated camera model.
    ///
    /// # Errors
    /// As [`Self::validate`].
    pub fn model(&self) -> Result<CameraModel, TrackerError> {
        let [w, h] = self.image_size_px;
        if !(3..=16384).contains(&w) || !(3..=16384).contains(&h) {
            return Err(field_error(
                "image_size_px",
                format!("[{w}, {h}]"),
                "each must be in 3..=16384",
            ));
        }
        let (camera, homography) = match (self.intrinsics, self.mounting, self.homography) {
            (Some(i), Some(m), None) => {
                let cam = PinholeCamera::new(
                    Intrinsics {
                        focal_length_px: i.focal_length_px,
                        principal_point_px: i.principal_point_px,
                    },
                    Mounting {
                        height_m: m.height_m,
                        pitch_down_rad: m.pitch_down_rad,
                        roll_rad: m.roll_rad,
                        yaw_rad: m.yaw_rad,
                    },
                )
                .map_err(geometry_field_error)?;
                let hom = cam.homography().map_err(geometry_field_error)?;
                (Some(cam), hom)
            }
            (None, None, Some(hc)) => (
                None,
                Homography::from_point_pairs(&hc.image_points_px, &hc.ground_points_m)
                    .map_err(geometry_field_error)?,
            ),
            (_, _, Some(_)) => {
                return Err(field_error(
                    "homography",
                    "given",
                    "give either [homography] or [intrinsics] + [mounting], not both",
                ));
            }
            (None, _, None) => {
                return Err(field_error(
                    "intrinsics",
                    "missing",
                    "give [intrinsics] + [mounting], or [homography]",
                ));
            }
            (Some(_), None, None) => {
                return Err(field_error(
                    "mounting",
                    "missing",
                    "[intrinsics] needs [mounting]",
                ));
            }
        };
        let la = self.lookahead;
        let ego =
            EgoLaneEstimator::new(homography, la.near_m, la.far_m).map_err(geometry_field_error)?;
        Ok(CameraModel {
            config: *self,
            camera,
            ego,
        })
    }
}

/// The camera model in use: the homography, the look-ahead sample rows and (for a modelled
/// camera) the pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraModel {
    config: CameraConfig,
    camera: Option<PinholeCamera>,
    ego: EgoLaneEstimator,
}

/// The ego lane of one frame, in metres (the per-frame JSON `ego_lane` object).
///
/// Signs: `lateral_offset_m > 0` when the camera is right of the lane centre; `heading_rad > 0`
/// when the vehicle points right of the lane; `curvature_per_m > 0` when the lane bends right.
/// Each `*_sigma` is the standard deviation propagated from the two lanes' coefficient
/// covariances (`lane-geometry` crate docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EgoLaneReport {
    /// Camera's distance from the lane centre line, m, right > 0.
    pub lateral_offset_m: f64,
    /// σ of `lateral_offset_m`, m.
    pub lateral_offset_m_sigma: f64,
    /// Vehicle heading relative to the lane, rad, right > 0.
    pub heading_rad: f64,
    /// σ of `heading_rad`, rad.
    pub heading_rad_sigma: f64,
    /// Curvature of the lane centre line, 1/m, bending right > 0.
    pub curvature_per_m: f64,
    /// σ of `curvature_per_m`, 1/m.
    pub curvature_per_m_sigma: f64,
    /// Lane width across the lane, m.
    pub lane_width_m: f64,
    /// σ of `lane_width_m`, m.
    pub lane_width_m_sigma: f64,
}

impl CameraModel {
    /// The configuration it was built from.
    pub fn config(&self) -> &CameraConfig {
        &self.config
    }

    /// The pinhole camera, for a modelled camera (`None` for a measured homography).
    pub fn camera(&self) -> Option<&PinholeCamera> {
        self.camera.as_ref()
    }

    /// The ground-plane homography.
    pub fn homography(&self) -> &Homography {
        self.ego.homography()
    }

    /// The ego-lane estimator (its look-ahead sample rows, the maths).
    pub fn estimator(&self) -> &EgoLaneEstimator {
        &self.ego
    }

    /// Refuses frames of another size than `image_size_px`.
    ///
    /// # Errors
    /// [`TrackerError::CameraFrameSize`].
    pub fn check_frame_size(&self, width: usize, height: usize) -> Result<(), TrackerError> {
        let [w, h] = self.config.image_size_px;
        if (w, h) == (width, height) {
            Ok(())
        } else {
            Err(TrackerError::CameraFrameSize {
                expected_w: w,
                expected_h: h,
                got_w: width,
                got_h: height,
            })
        }
    }

    /// The ego lane after `tracker` produced `report`: `Some` when both lanes are held
    /// (tracking or coasting) with a covariance and the geometry is defined (their sample points
    /// below the horizon); no allocation.
    pub fn ego_lane(&self, tracker: &LaneTracker, report: &TrackReport) -> Option<EgoLaneReport> {
        let [l, r] = &report.lanes;
        let (lc, rc) = (l.coeffs?, r.coeffs?);
        let lp = tracker.lane_covariance_px(Side::Left)?;
        let rp = tracker.lane_covariance_px(Side::Right)?;
        let fit = [
            tracker.lane_fit_rows(Side::Left)?,
            tracker.lane_fit_rows(Side::Right)?,
        ];
        self.ego_lane_from(&lc, &lp, &rc, &rp, Some(&fit))
    }

    /// The ego lane from two lanes' coefficients `[a1, a2, a3]` (px) and covariances (pixel
    /// parameterisation); `None` if the geometry is undefined for them. With `fit` (how each
    /// lane was fitted, [`LaneTracker::lane_fit_rows`], left then right) the image-parabola
    /// model error is removed (`lane_geometry::EgoLaneEstimator::estimate_fitted`).
    pub fn ego_lane_from(
        &self,
        left_px: &[f64; 3],
        left_cov_px: &Matrix3<f64>,
        right_px: &[f64; 3],
        right_cov_px: &Matrix3<f64>,
        fit: Option<&[FitRows; 2]>,
    ) -> Option<EgoLaneReport> {
        let e = match fit {
            Some(rows) => {
                self.ego
                    .estimate_fitted(left_px, left_cov_px, right_px, right_cov_px, rows)
            }
            None => self
                .ego
                .estimate(left_px, left_cov_px, right_px, right_cov_px),
        }
        .ok()?;
        Some(EgoLaneReport {
            lateral_offset_m: e.geometry.lateral_offset_m,
            lateral_offset_m_sigma: e.sigma.lateral_offset_m,
            heading_rad: e.geometry.heading_rad,
            heading_rad_sigma: e.sigma.heading_rad,
            curvature_per_m: e.geometry.curvature_per_m,
            curvature_per_m_sigma: e.sigma.curvature_per_m,
            lane_width_m: e.geometry.lane_width_m,
            lane_width_m_sigma: e.sigma.lane_width_m,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_parse_and_validate() {
        let robot = CameraConfig::preset("robot").unwrap().unwrap();
        let highway = CameraConfig::preset("highway").unwrap().unwrap();
        assert_eq!(robot.image_size_px, [320, 240]);
        assert_eq!(highway.image_size_px, [320, 240]);
        assert!(robot.mounting.unwrap().height_m < highway.mounting.unwrap().height_m);
    }

    #[test]
    fn unknown_and_missing_fields_are_named() {
        let text = CAMERA_ROBOT_TOML.replace("[mounting]", "[mounting]\nheight = 0.3");
        let msg = CameraConfig::from_toml_str("c.toml", &text)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("height") && msg.contains("c.toml"), "{msg}");
        let text: String = CAMERA_ROBOT_TOML
            .lines()
            .filter(|l| !l.starts_with("far_m"))
            .map(|l| format!("{l}\n"))
            .collect();
        let msg = CameraConfig::from_toml_str("c.toml", &text)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("far_m"), "{msg}");
    }

    #[test]
    fn each_out_of_range_field_is_named() {
        type Edit = fn(&mut CameraConfig);
        let cases: &[(&str, Edit)] = &[
            ("image_size_px", |c| c.image_size_px = [0, 240]),
            ("intrinsics.focal_length_px", |c| {
                c.intrinsics.as_mut().unwrap().focal_length_px = -1.0
            }),
            ("intrinsics.principal_point_px", |c| {
                c.intrinsics.as_mut().unwrap().principal_point_px[1] = f64::NAN
            }),
            ("mounting.height_m", |c| {
                c.mounting.as_mut().unwrap().height_m = 0.0
            }),
            ("mounting.pitch_down_rad", |c| {
                c.mounting.as_mut().unwrap().pitch_down_rad = 3.0
            }),
            ("mounting.roll_rad", |c| {
                c.mounting.as_mut().unwrap().roll_rad = f64::NAN
            }),
            ("mounting.yaw_rad", |c| {
                c.mounting.as_mut().unwrap().yaw_rad = -2.0
            }),
            ("lookahead.near_m", |c| c.lookahead.near_m = 0.0),
            ("lookahead.far_m", |c| c.lookahead.far_m = 0.1),
            ("mounting", |c| c.mounting = None),
            ("intrinsics", |c| {
                c.intrinsics = None;
                c.mounting = None;
            }),
            ("homography", |c| {
                c.homography = Some(HomographyConfig {
                    image_points_px: [[0.0, 200.0], [300.0, 200.0], [100.0, 150.0], [200.0, 150.0]],
                    ground_points_m: [[1.0, -1.0], [1.0, 1.0], [3.0, -1.0], [3.0, 1.0]],
                })
            }),
        ];
        for (field, edit) in cases {
            let mut cfg = CameraConfig::preset("robot").unwrap().unwrap();
            edit(&mut cfg);
            match cfg.validate() {
                Err(e) if e.config_field().is_some() => {
                    assert_eq!(e.config_field(), Some(*field), "{e}");
                }
                other => panic!("{field}: expected a field error, got {other:?}"),
            }
        }
    }

    #[test]
    fn a_measured_homography_gives_the_same_lane_as_the_modelled_camera() {
        let modelled = CameraConfig::preset("robot")
            .unwrap()
            .unwrap()
            .model()
            .unwrap();
        let h = modelled.homography();
        let ground = [[0.6, -0.4], [0.6, 0.4], [1.2, -0.5], [1.2, 0.5]];
        let image = ground.map(|g| h.ground_to_image(g).unwrap());
        let mut cfg = CameraConfig::preset("robot").unwrap().unwrap();
        cfg.intrinsics = None;
        cfg.mounting = None;
        cfg.homography = Some(HomographyConfig {
            image_points_px: image,
            ground_points_m: ground,
        });
        let measured = cfg.model().unwrap();
        // The look-ahead rows come from the homography alone, so they agree too.
        let cov = Matrix3::from_diagonal(&nalgebra::Vector3::new(1e-9, 1e-4, 0.5));
        let (l, r) = ([2e-4, -1.2, 300.0], [2e-4, 0.9, 10.0]);
        let a = modelled.ego_lane_from(&l, &cov, &r, &cov, None).unwrap();
        let b = measured.ego_lane_from(&l, &cov, &r, &cov, None).unwrap();
        assert!(
            (a.lateral_offset_m - b.lateral_offset_m).abs() < 1e-6,
            "{a:?} {b:?}"
        );
        assert!((a.heading_rad - b.heading_rad).abs() < 1e-6);
        assert!((a.lane_width_m_sigma - b.lane_width_m_sigma).abs() < 1e-6);
        // A round trip through TOML keeps it.
        let text = toml::to_string(&cfg).unwrap();
        assert_eq!(CameraConfig::from_toml_str("rt", &text).unwrap(), cfg);
    }

    #[test]
    fn a_value_the_geometry_refuses_keeps_its_error_and_a_frame_of_another_size_is_named() {
        use std::error::Error as _;
        let mut cfg = CameraConfig::preset("robot").unwrap().unwrap();
        if let Some(m) = cfg.mounting.as_mut() {
            m.height_m = -1.0;
        }
        let e = cfg.validate().expect_err("refused");
        assert_eq!(e.config_field(), Some("mounting.height_m"), "{e}");
        assert!(
            e.source()
                .and_then(|s| s.downcast_ref::<GeometryError>())
                .is_some(),
            "{e:?}"
        );
        let model = CameraConfig::preset("robot")
            .unwrap()
            .unwrap()
            .model()
            .unwrap();
        assert!(model.check_frame_size(320, 240).is_ok());
        let e = model.check_frame_size(640, 480).expect_err("another size");
        assert!(
            matches!(
                e,
                TrackerError::CameraFrameSize {
                    expected_w: 320,
                    expected_h: 240,
                    got_w: 640,
                    got_h: 480
                }
            ),
            "{e:?}"
        );
        assert!(e.to_string().contains("image_size_px"), "{e}");
    }
}
