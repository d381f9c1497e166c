//! The per-frame lane record: the object `nav-app --json` prints for each frame and the message
//! the MCAP `/lanes` channel carries ([`crate::mcap_sink`]), one type for both, described by the
//! JSON schema [`crate::mcap_sink::LANES_SCHEMA`] (`docs/json.md` documents its fields).

use lane_tracker::camera::EgoLaneReport;
use lane_tracker::{FrameExposure, FrameNoise, LaneReport, RoadReport};
use serde::Serialize;

use crate::capture_source::DeviceFrameInfo;

/// Version of the per-frame objects (and of `nav-app --json`'s summary line). Raised when a
/// field changes meaning or disappears; new fields do not raise it.
pub const LANE_FRAME_SCHEMA: u32 = 1;

/// One tracked frame, as `nav-app --json` prints it and `/lanes` carries it.
#[derive(Debug, Clone, Serialize)]
pub struct LaneFrame<'a> {
    /// [`LANE_FRAME_SCHEMA`].
    pub schema: u32,
    /// The frame's index in the input.
    pub frame: u64,
    /// The frame's time stamp, s.
    pub t_s: f64,
    /// Left then right.
    pub lanes: &'a [LaneReport; 2],
    /// The road region the frame was searched in: the road's bottom row, the rows searched and
    /// the horizon the ego lanes show (`lane_tracker::RoadReport`).
    pub road: RoadReport,
    /// The frames' exposure as last measured and the gain they are brightened by before tracking
    /// (`lane_tracker::FrameExposure`, `[exposure]`).
    pub exposure: FrameExposure,
    /// The frames' noise as last measured and whether they are smoothed before tracking
    /// (`lane_tracker::FrameNoise`, `[denoise]`).
    pub noise: FrameNoise,
    /// Wall time of `LaneTracker::track` on this frame, µs.
    pub track_us: f64,
    /// The ego lane in metres with σ (with a camera; `null` unless both lanes are held; absent
    /// without a camera).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ego_lane: Option<Option<EgoLaneReport>>,
    /// Each lane's coefficient covariance in pixels (`null` for a lane without an estimate;
    /// absent when not asked for).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lane_cov_px: Option<[Option<[[f64; 3]; 3]>; 2]>,
    /// Device fields (a capture device only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capture: Option<DeviceFrameInfo>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcap_sink::LANES_SCHEMA;
    use lane_tracker::{LaneState, Side};

    fn lane(side: Side) -> LaneReport {
        LaneReport {
            side,
            state: LaneState::Tracking,
            coeffs: Some([0.001, -0.5, 100.0]),
            rows: [150.0, 239.0],
            points: 42,
            initialised: false,
            far: None,
        }
    }

    /// The schema's top-level and per-lane `properties` and `required` keys.
    fn schema_keys(schema: &serde_json::Value, at: &str) -> (Vec<String>, Vec<String>) {
        let node = schema.pointer(at).expect("a schema node");
        let props = node["properties"]
            .as_object()
            .expect("properties")
            .keys()
            .cloned()
            .collect();
        let required = node["required"]
            .as_array()
            .expect("required")
            .iter()
            .map(|v| v.as_str().expect("a key").to_owned())
            .collect();
        (props, required)
    }

    #[test]
    fn the_record_and_the_mcap_schema_name_the_same_fields() {
        let schema: serde_json::Value = serde_json::from_str(LANES_SCHEMA).expect("valid JSON");
        let lanes = [lane(Side::Left), lane(Side::Right)];
        let full = LaneFrame {
            schema: LANE_FRAME_SCHEMA,
            frame: 7,
            t_s: 0.28,
            lanes: &lanes,
            road: RoadReport {
                bottom_row_px: 240.0,
                search_rows_px: [148.0, 240.0],
                horizon_row_px: Some(96.5),
                refused: None,
            },
            exposure: FrameExposure {
                median_grey: 42.0,
                gain: 50.0 / 42.0,
            },
            noise: FrameNoise {
                sigma_grey: 1.7,
                denoised: false,
            },
            track_us: 31.0,
            ego_lane: Some(None),
            lane_cov_px: Some([Some([[1.0; 3]; 3]), None]),
            capture: None,
        };
        let bare = LaneFrame {
            ego_lane: None,
            lane_cov_px: None,
            ..full.clone()
        };
        let (props, required) = schema_keys(&schema, "");
        let (lane_props, lane_required) = schema_keys(&schema, "/properties/lanes/items");
        for record in [&full, &bare] {
            let v = serde_json::to_value(record).expect("serialisable");
            let obj = v.as_object().expect("an object");
            // Every field the record writes is in the schema, every required one is written.
            for key in obj.keys().filter(|k| *k != "capture") {
                assert!(props.contains(key), "`{key}` is not in LANES_SCHEMA");
            }
            for key in &required {
                assert!(obj.contains_key(key), "required `{key}` missing");
            }
            assert_eq!(obj["schema"], serde_json::json!(LANE_FRAME_SCHEMA));
            for lane in v["lanes"].as_array().expect("lanes") {
                let lane = lane.as_object().expect("a lane object");
                for key in lane.keys() {
                    assert!(
                        lane_props.contains(key),
                        "lane `{key}` is not in LANES_SCHEMA"
                    );
                }
                for key in &lane_required {
                    assert!(lane.contains_key(key), "lane's required `{key}` missing");
                }
            }
        }
        // The schema's own version is the record's.
        assert_eq!(
            schema.pointer("/properties/schema/const"),
            Some(&serde_json::json!(LANE_FRAME_SCHEMA))
        );
    }
}
