//! The lanes as an MCAP file for Foxglove (`nav-app --mcap-out`): per frame, the grey frame as
//! `foxglove.RawImage` on `/camera/image`, both lanes drawn on it as polylines
//! (`foxglove.ImageAnnotations` on `/camera/lanes`: left blue, right orange, over the rows of the
//! points behind each estimate), and the lane estimate itself as JSON on `/lanes` (the object
//! `nav-app --json` prints for the frame, [`LaneFrame`](crate::lane_frame::LaneFrame), with its JSON schema [`LANES_SCHEMA`]). Opening the
//! file in Foxglove's Image panel on `/camera/image` with `/camera/lanes` as annotations shows
//! the camera with the lanes on it; the Plot panel plots `/lanes.lanes[0].coeffs[2]` and the rest.
//! With a camera model (`--camera`), a fourth channel, `/camera/birdseye`, carries the bird's-eye
//! view ([`crate::birdseye`]) as `foxglove.RawImage` (rgb8).
//!
//! The messages are encoded once ([`LaneEncoder`]; `/lanes` is the `--json` line itself) and the
//! same bytes go to the file ([`LaneMcapSink::write_encoded`]) and to a live Foxglove connection
//! (`nav-app --foxglove`), whose channels are [`lane_channels`].

use grey_frame::GreyFrame;
use lane_tracker::TrackReport;
use ros_bag::out::foxglove::{
    Color, IMAGE_ANNOTATIONS, ImageAnnotations, LINE_STRIP, Point2, PointsAnnotation, RAW_IMAGE,
    RawImage, Time, image_annotations_schema, raw_image_schema,
};
use ros_bag::out::{JsonChannel, JsonMcapWriter, base64_append, base64_into};

use crate::LaneIoError;
use crate::birdseye::BirdseyeView;

/// Topic of the grey frames.
pub const IMAGE_TOPIC: &str = "/camera/image";
/// Topic of the lane polylines.
pub const ANNOTATIONS_TOPIC: &str = "/camera/lanes";
/// Topic of the lane estimates.
pub const LANES_TOPIC: &str = "/lanes";
/// Topic of the bird's-eye view (with a camera model).
pub const BIRDSEYE_TOPIC: &str = "/camera/birdseye";

/// Index of the image channel in [`lane_channels`] (and in a `wants` array).
pub const IMAGE: usize = 0;
/// Index of the annotations channel.
pub const ANNOTATIONS: usize = 1;
/// Index of the lanes channel.
pub const LANES: usize = 2;
/// Index of the bird's-eye channel, after [`lane_channels`]' three ([`birdseye_channel`]).
pub const BIRDSEYE: usize = 3;
/// Schema name of the lane estimates.
pub const LANES_SCHEMA_NAME: &str = "ita_nav.LaneFrame";

/// JSON schema of the `/lanes` messages (`nav-app --json`'s per-frame object, schema 1).
pub const LANES_SCHEMA: &str = r#"{"title":"ita_nav.LaneFrame","description":"One frame of nav-app's lane tracker (lane_io::lane_frame::LaneFrame, the --json object, schema 1)","type":"object","properties":{"schema":{"type":"integer","const":1},"frame":{"type":"integer","minimum":0},"t_s":{"type":"number"},"lanes":{"type":"array","minItems":2,"maxItems":2,"items":{"type":"object","properties":{"side":{"enum":["left","right"]},"state":{"enum":["initialising","tracking","coasting","lost"]},"coeffs":{"type":["array","null"],"items":{"type":"number"},"minItems":3,"maxItems":3,"description":"[a1, a2, a3] of x = a1 y^2 + a2 y + a3, pixels of the input image"},"rows":{"type":"array","items":{"type":"number"},"minItems":2,"maxItems":2},"points":{"type":"integer","minimum":0},"initialised":{"type":"boolean"},"far":{"type":["object","null"],"properties":{"coeffs":{"type":"array","items":{"type":"number"},"minItems":3,"maxItems":3},"rows":{"type":"array","items":{"type":"number"},"minItems":2,"maxItems":2}},"description":"the far segment above the near parabola's rows: [a1, a2, a3] on rows [y_min, y_join]"}},"required":["side","state","coeffs","rows","points","initialised","far"]}},"road":{"type":"object","properties":{"bottom_row_px":{"type":"number","description":"one past the lowest row of road, pixels of the input image"},"search_rows_px":{"type":"array","items":{"type":"number"},"minItems":2,"maxItems":2,"description":"[top, bottom) rows searched for lanes"},"horizon_row_px":{"type":["number","null"],"description":"row where the two ego lanes' tangents meet"},"refused":{"enum":["lanes_diverge_upwards","lanes_crossed",null],"description":"why the region the lanes show was refused"}},"required":["bottom_row_px","search_rows_px","horizon_row_px","refused"]},"exposure":{"type":"object","properties":{"median_grey":{"type":"number","minimum":0,"description":"the median grey of the rows searched as last measured (0: not measured)"},"gain":{"type":"number","minimum":1,"description":"the factor the frames' grey levels are multiplied by before tracking (1: as they are)"}},"required":["median_grey","gain"]},"noise":{"type":"object","properties":{"sigma_grey":{"type":"number","minimum":0,"description":"the frames' noise sigma as last measured on the rows searched, grey levels (0: not measured)"},"denoised":{"type":"boolean","description":"whether the frames are smoothed before tracking"}},"required":["sigma_grey","denoised"]},"track_us":{"type":"number"},"ego_lane":{"type":["object","null"]},"lane_cov_px":{"type":["array","null"]}},"required":["schema","frame","t_s","lanes","road","exposure","noise","track_us"]}"#;

const COLOURS: [Color; 2] = [
    Color {
        r: 0.1,
        g: 0.5,
        b: 1.0,
        a: 1.0,
    },
    Color {
        r: 1.0,
        g: 0.5,
        b: 0.0,
        a: 1.0,
    },
];
/// The road region's lines across the image: the road's bottom (where a bonnet or a dashboard
/// ends it above the frame's last row) yellow, the horizon the lanes show cyan.
const ROAD_BOTTOM_COLOUR: Color = Color {
    r: 1.0,
    g: 1.0,
    b: 0.0,
    a: 0.8,
};
const HORIZON_COLOUR: Color = Color {
    r: 0.0,
    g: 1.0,
    b: 1.0,
    a: 0.8,
};
const NO_FILL: Color = Color {
    r: 0.0,
    g: 0.0,
    b: 0.0,
    a: 0.0,
};
/// Vertices per lane polyline.
const POLYLINE_POINTS: usize = 24;

/// The lane channels, in the order image, annotations, lanes: (topic, schema name, JSON schema).
pub fn lane_channels() -> [(&'static str, &'static str, String); 3] {
    [
        (IMAGE_TOPIC, RAW_IMAGE, raw_image_schema()),
        (
            ANNOTATIONS_TOPIC,
            IMAGE_ANNOTATIONS,
            image_annotations_schema(),
        ),
        (LANES_TOPIC, LANES_SCHEMA_NAME, LANES_SCHEMA.to_owned()),
    ]
}

/// The bird's-eye channel, index [`BIRDSEYE`] when added after [`lane_channels`]: (topic,
/// schema name, JSON schema).
pub fn birdseye_channel() -> (&'static str, &'static str, String) {
    (BIRDSEYE_TOPIC, RAW_IMAGE, raw_image_schema())
}

/// A frame's time in nanoseconds, as the channels carry it: `round(max(t_s, 0)·1e9)`.
pub fn frame_t_ns(t_s: f64) -> u64 {
    (t_s.max(0.0) * 1e9).round() as u64
}

/// Encodes the `/camera/image`, `/camera/lanes` and `/camera/birdseye` messages as JSON into
/// buffers it keeps, so that one encoding serves the file and the live connection alike.
#[derive(Debug, Default)]
pub struct LaneEncoder {
    base64: String,
    ann: ImageAnnotations,
    image: Vec<u8>,
    annotations: Vec<u8>,
    birdseye: Vec<u8>,
}

/// `image` with `pixels` (its `data`) as JSON into `out`.
fn encode_raw_image(
    topic: &'static str,
    out: &mut Vec<u8>,
    base64: &mut String,
    image: RawImage<'_>,
    pixels: &[u8],
) -> Result<(), LaneIoError> {
    // The message with an empty `data` (its last field) through serde, then the pixels'
    // base64 appended in place: the same bytes as serialising it whole (base64 needs no
    // escaping), without the string's copy and escape scan.
    encode(topic, out, &image)?;
    if out.ends_with(b"\"\"}") {
        out.truncate(out.len() - 2);
        base64_append(pixels, out);
        out.extend_from_slice(b"\"}");
        return Ok(());
    }
    base64_into(pixels, base64);
    let image = RawImage {
        data: base64,
        ..image
    };
    encode(topic, out, &image)
}

fn encode(
    topic: &'static str,
    out: &mut Vec<u8>,
    message: &impl serde::Serialize,
) -> Result<(), LaneIoError> {
    out.clear();
    serde_json::to_writer(&mut *out, message)
        .map_err(|source| LaneIoError::Encode { topic, source })
}

impl LaneEncoder {
    /// Encodes the frame as `foxglove.RawImage` (mono8, base64) at `t_ns`: [`Self::image_json`].
    ///
    /// # Errors
    /// [`LaneIoError::Encode`].
    pub fn encode_image(&mut self, t_ns: u64, frame: &GreyFrame) -> Result<(), LaneIoError> {
        let image = RawImage {
            timestamp: Time::from_ns(t_ns),
            frame_id: "camera",
            width: frame.width() as u32,
            height: frame.height() as u32,
            encoding: "mono8",
            step: frame.width() as u32,
            data: "",
        };
        encode_raw_image(
            IMAGE_TOPIC,
            &mut self.image,
            &mut self.base64,
            image,
            frame.data(),
        )
    }

    /// Encodes the bird's-eye view `rgb` (as [`BirdseyeView::render`] fills it) as
    /// `foxglove.RawImage` (rgb8, frame `birdseye`) at `t_ns`: [`Self::birdseye_json`].
    ///
    /// # Errors
    /// [`LaneIoError::Encode`].
    pub fn encode_birdseye(
        &mut self,
        t_ns: u64,
        view: &BirdseyeView,
        rgb: &[u8],
    ) -> Result<(), LaneIoError> {
        let image = RawImage {
            timestamp: Time::from_ns(t_ns),
            frame_id: "birdseye",
            width: view.width_px() as u32,
            height: view.height_px() as u32,
            encoding: "rgb8",
            step: 3 * view.width_px() as u32,
            data: "",
        };
        encode_raw_image(
            BIRDSEYE_TOPIC,
            &mut self.birdseye,
            &mut self.base64,
            image,
            rgb,
        )
    }

    /// The last image encoded, JSON.
    pub fn image_json(&self) -> &[u8] {
        &self.image
    }

    /// The last bird's-eye view encoded, JSON.
    pub fn birdseye_json(&self) -> &[u8] {
        &self.birdseye
    }

    /// The last annotations encoded, JSON.
    pub fn annotations_json(&self) -> &[u8] {
        &self.annotations
    }

    /// Encodes the lanes of `report` as polylines on the `width_px`×`height_px` frame, with the
    /// road's bottom and horizon lines (`foxglove.ImageAnnotations`) at `t_ns`:
    /// [`Self::annotations_json`].
    ///
    /// # Errors
    /// [`LaneIoError::Encode`].
    pub fn encode_annotations(
        &mut self,
        t_ns: u64,
        width_px: usize,
        height_px: usize,
        report: &TrackReport,
    ) -> Result<(), LaneIoError> {
        let timestamp = Time::from_ns(t_ns);
        self.ann.points.clear();
        for (lane, colour) in report.lanes.iter().zip(COLOURS) {
            let Some(_) = lane.coeffs else { continue };
            let [top, bottom] = lane.rows;
            let points = (0..POLYLINE_POINTS)
                .filter_map(|k| {
                    let y = top + (bottom - top) * k as f64 / (POLYLINE_POINTS - 1) as f64;
                    lane.col_seen_at_row(y).map(|x| Point2 { x, y })
                })
                .collect();
            self.ann.points.push(PointsAnnotation {
                timestamp,
                kind: LINE_STRIP,
                points,
                outline_color: colour,
                outline_colors: Vec::new(),
                fill_color: NO_FILL,
                thickness: 3.0,
            });
        }
        let width = width_px as f64;
        let road = report.road;
        let lines = [
            (
                road.bottom_row_px,
                ROAD_BOTTOM_COLOUR,
                road.bottom_row_px < height_px as f64,
            ),
            (
                road.horizon_row_px.unwrap_or(0.0),
                HORIZON_COLOUR,
                road.horizon_row_px.is_some(),
            ),
        ];
        for (y, colour, shown) in lines {
            if shown {
                self.ann.points.push(PointsAnnotation {
                    timestamp,
                    kind: LINE_STRIP,
                    points: vec![Point2 { x: 0.0, y }, Point2 { x: width, y }],
                    outline_color: colour,
                    outline_colors: Vec::new(),
                    fill_color: NO_FILL,
                    thickness: 1.0,
                });
            }
        }
        encode(ANNOTATIONS_TOPIC, &mut self.annotations, &self.ann)
    }
}

/// An open `--mcap-out` file.
#[derive(Debug)]
pub struct LaneMcapSink {
    writer: JsonMcapWriter,
    channels: [JsonChannel; 3],
    birdseye: Option<JsonChannel>,
}

fn bag(source: ros_bag::BagError) -> LaneIoError {
    LaneIoError::Bag { source }
}

impl LaneMcapSink {
    /// Creates the file and its three channels ([`lane_channels`]).
    ///
    /// # Errors
    /// [`LaneIoError::Bag`] when the file cannot be created.
    pub fn create(path: &std::path::Path) -> Result<Self, LaneIoError> {
        let mut writer = JsonMcapWriter::create(&path.display().to_string()).map_err(bag)?;
        let mut channels = Vec::with_capacity(3);
        for (topic, name, schema) in lane_channels() {
            channels.push(writer.channel(topic, name, &schema).map_err(bag)?);
        }
        let channels = [channels[0], channels[1], channels[2]];
        Ok(Self {
            writer,
            channels,
            birdseye: None,
        })
    }

    /// Adds the bird's-eye channel ([`birdseye_channel`]): from then on
    /// [`Self::write_encoded`] writes the encoder's bird's-eye view too.
    ///
    /// # Errors
    /// [`LaneIoError::Bag`].
    pub fn add_birdseye_channel(&mut self) -> Result<(), LaneIoError> {
        let (topic, name, schema) = birdseye_channel();
        self.birdseye = Some(self.writer.channel(topic, name, &schema).map_err(bag)?);
        Ok(())
    }

    /// Writes one frame's messages already encoded: the image, the annotations and (with the
    /// bird's-eye channel added) the bird's-eye view as `encoder` last encoded them, and `lanes`,
    /// the [`LaneFrame`](crate::lane_frame::LaneFrame) as JSON (the `--json` line without its newline).
    ///
    /// # Errors
    /// [`LaneIoError::Bag`].
    pub fn write_encoded(
        &mut self,
        t_ns: u64,
        encoder: &LaneEncoder,
        lanes: &[u8],
    ) -> Result<(), LaneIoError> {
        let [image, annotations, lanes_channel] = self.channels;
        let messages = [
            (Some(image), encoder.image_json()),
            (Some(annotations), encoder.annotations_json()),
            (Some(lanes_channel), lanes),
            (self.birdseye, encoder.birdseye_json()),
        ];
        for (channel, json) in messages {
            if let Some(channel) = channel {
                self.writer
                    .write_json_bytes(channel, t_ns, json)
                    .map_err(bag)?;
            }
        }
        Ok(())
    }

    /// Writes the summary and closes the file.
    ///
    /// # Errors
    /// [`LaneIoError::Bag`].
    pub fn finish(self) -> Result<(), LaneIoError> {
        self.writer.finish().map_err(bag)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_image_is_the_bytes_serde_gives_the_whole_message() {
        for (w, h) in [(4, 3), (5, 1), (7, 2)] {
            let data: Vec<u8> = (0..w * h).map(|k| (k * 37 % 256) as u8).collect();
            let frame = GreyFrame::from_vec(w, h, data).unwrap();
            let mut encoder = LaneEncoder::default();
            encoder.encode_image(1_500_000_001, &frame).unwrap();
            let mut text = String::new();
            base64_into(frame.data(), &mut text);
            let whole = serde_json::to_vec(&RawImage {
                timestamp: Time::from_ns(1_500_000_001),
                frame_id: "camera",
                width: w as u32,
                height: h as u32,
                encoding: "mono8",
                step: w as u32,
                data: &text,
            })
            .unwrap();
            assert_eq!(
                String::from_utf8_lossy(encoder.image_json()),
                String::from_utf8_lossy(&whole)
            );
        }
    }
}
