//! Writing MCAP files of JSON-encoded channels with JSON schemas (what Foxglove reads), and the
//! Foxglove message types the lane tracker writes: [`foxglove::RawImage`] (the grey frame) and
//! [`foxglove::ImageAnnotations`] (lanes drawn as polylines on it).

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;

use serde::Serialize;

use crate::BagError;

/// An MCAP file being written: JSON channels, one schema each.
pub struct JsonMcapWriter {
    path: String,
    writer: mcap::Writer<BufWriter<File>>,
    topics: Vec<String>,
    sequence: u32,
    scratch: Vec<u8>,
}

impl std::fmt::Debug for JsonMcapWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("JsonMcapWriter")
            .field("path", &self.path)
            .field("topics", &self.topics)
            .finish()
    }
}

/// A channel of a [`JsonMcapWriter`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JsonChannel(u16, usize);

impl JsonMcapWriter {
    /// Creates the file (zstd-compressed chunks, with a summary).
    ///
    /// # Errors
    /// [`BagError::Io`], [`BagError::Mcap`].
    pub fn create(path: &str) -> Result<Self, BagError> {
        let file = File::create(path).map_err(|source| BagError::Io {
            path: path.to_owned(),
            source,
        })?;
        let writer = mcap::Writer::new(BufWriter::new(file)).map_err(|source| BagError::Mcap {
            path: path.to_owned(),
            source,
        })?;
        Ok(Self {
            path: path.to_owned(),
            writer,
            topics: Vec::new(),
            sequence: 0,
            scratch: Vec::with_capacity(1 << 16),
        })
    }

    fn mcap_err(&self) -> impl Fn(mcap::McapError) -> BagError + '_ {
        move |source| BagError::Mcap {
            path: self.path.clone(),
            source,
        }
    }

    /// Adds a channel on `topic` whose messages follow the JSON schema `schema_json` named
    /// `schema_name`.
    ///
    /// # Errors
    /// [`BagError::Mcap`].
    pub fn channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema_json: &str,
    ) -> Result<JsonChannel, BagError> {
        let schema = self
            .writer
            .add_schema(schema_name, "jsonschema", schema_json.as_bytes())
            .map_err(|source| BagError::Mcap {
                path: self.path.clone(),
                source,
            })?;
        let id = self
            .writer
            .add_channel(schema, topic, "json", &BTreeMap::new())
            .map_err(|source| BagError::Mcap {
                path: self.path.clone(),
                source,
            })?;
        self.topics.push(topic.to_owned());
        Ok(JsonChannel(id, self.topics.len() - 1))
    }

    /// Writes `message` as JSON on `channel` at `t_ns` (log and publish time).
    ///
    /// # Errors
    /// [`BagError::Json`], [`BagError::Mcap`].
    pub fn write(
        &mut self,
        channel: JsonChannel,
        t_ns: u64,
        message: &impl Serialize,
    ) -> Result<(), BagError> {
        self.scratch.clear();
        serde_json::to_writer(&mut self.scratch, message).map_err(|source| BagError::Json {
            path: self.path.clone(),
            topic: self.topics[channel.1].clone(),
            source,
        })?;
        let data = std::mem::take(&mut self.scratch);
        let r = self.write_json_bytes(channel, t_ns, &data);
        self.scratch = data;
        r
    }

    /// Writes `json`, a message already serialized as JSON (the same bytes another sink, such as a
    /// live server, receives), on `channel` at `t_ns` (log and publish time).
    ///
    /// # Errors
    /// [`BagError::Mcap`].
    pub fn write_json_bytes(
        &mut self,
        channel: JsonChannel,
        t_ns: u64,
        json: &[u8],
    ) -> Result<(), BagError> {
        self.sequence += 1;
        let header = mcap::records::MessageHeader {
            channel_id: channel.0,
            sequence: self.sequence,
            log_time: t_ns,
            publish_time: t_ns,
        };
        self.writer
            .write_to_known_channel(&header, json)
            .map_err(self.mcap_err())
    }

    /// Writes the summary and closes the file.
    ///
    /// # Errors
    /// [`BagError::Mcap`].
    pub fn finish(mut self) -> Result<(), BagError> {
        self.writer.finish().map_err(self.mcap_err())?;
        Ok(())
    }
}

/// Appends `bytes` as standard base64 (RFC 4648, with padding) to `out`, 3 bytes to 4 characters
/// at a time: the same text as [`base64_into`], for a caller that writes JSON bytes itself.
pub fn base64_append(bytes: &[u8], out: &mut Vec<u8>) {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    out.reserve(bytes.len().div_ceil(3) * 4);
    let mut chunks = bytes.chunks_exact(3);
    for c in &mut chunks {
        let n = (u32::from(c[0]) << 16) | (u32::from(c[1]) << 8) | u32::from(c[2]);
        out.extend_from_slice(&[
            A[(n >> 18) as usize & 63],
            A[(n >> 12) as usize & 63],
            A[(n >> 6) as usize & 63],
            A[n as usize & 63],
        ]);
    }
    match *chunks.remainder() {
        [a] => {
            let n = u32::from(a) << 16;
            out.extend_from_slice(&[
                A[(n >> 18) as usize & 63],
                A[(n >> 12) as usize & 63],
                b'=',
                b'=',
            ]);
        }
        [a, b] => {
            let n = (u32::from(a) << 16) | (u32::from(b) << 8);
            out.extend_from_slice(&[
                A[(n >> 18) as usize & 63],
                A[(n >> 12) as usize & 63],
                A[(n >> 6) as usize & 63],
                b'=',
            ]);
        }
        _ => {}
    }
}

/// Standard base64 (RFC 4648, with padding), how JSON carries Foxglove's `bytes` fields.
pub fn base64_into(bytes: &[u8], out: &mut String) {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    out.clear();
    out.reserve(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= c.len() {
                out.push(A[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
}

/// Foxglove's message types (JSON encoding) used here, with their JSON schemas.
pub mod foxglove {
    use serde::Serialize;

    /// Schema name of [`RawImage`].
    pub const RAW_IMAGE: &str = "foxglove.RawImage";
    /// Schema name of [`ImageAnnotations`].
    pub const IMAGE_ANNOTATIONS: &str = "foxglove.ImageAnnotations";

    const TIME: &str = r#"{"type":"object","properties":{"sec":{"type":"integer","minimum":0},"nsec":{"type":"integer","minimum":0,"maximum":999999999}},"required":["sec","nsec"]}"#;

    /// JSON schema of [`RawImage`] (Foxglove's, the fields used here).
    pub fn raw_image_schema() -> String {
        format!(
            r#"{{"title":"foxglove.RawImage","description":"A raw image","type":"object","properties":{{"timestamp":{TIME},"frame_id":{{"type":"string"}},"width":{{"type":"integer","minimum":0}},"height":{{"type":"integer","minimum":0}},"encoding":{{"type":"string"}},"step":{{"type":"integer","minimum":0}},"data":{{"type":"string","contentEncoding":"base64"}}}},"required":["timestamp","frame_id","width","height","encoding","step","data"]}}"#
        )
    }

    /// JSON schema of [`ImageAnnotations`] (Foxglove's, the fields used here).
    pub fn image_annotations_schema() -> String {
        let colour = r#"{"type":"object","properties":{"r":{"type":"number"},"g":{"type":"number"},"b":{"type":"number"},"a":{"type":"number"}},"required":["r","g","b","a"]}"#;
        let point = r#"{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"}},"required":["x","y"]}"#;
        format!(
            r#"{{"title":"foxglove.ImageAnnotations","description":"Annotations on an image","type":"object","properties":{{"circles":{{"type":"array"}},"points":{{"type":"array","items":{{"type":"object","properties":{{"timestamp":{TIME},"type":{{"type":"integer","description":"0 UNKNOWN, 1 POINTS, 2 LINE_LOOP, 3 LINE_STRIP, 4 LINE_LIST"}},"points":{{"type":"array","items":{point}}},"outline_color":{colour},"outline_colors":{{"type":"array","items":{colour}}},"fill_color":{colour},"thickness":{{"type":"number","minimum":0}}}},"required":["timestamp","type","points","outline_color","outline_colors","fill_color","thickness"]}}}},"texts":{{"type":"array"}}}},"required":["circles","points","texts"]}}"#
        )
    }

    /// Schema name of [`LocationFix`].
    pub const LOCATION_FIX: &str = "foxglove.LocationFix";

    /// JSON schema of [`LocationFix`] (Foxglove's, the fields used here).
    pub fn location_fix_schema() -> String {
        format!(
            r#"{{"title":"foxglove.LocationFix","description":"A navigation satellite fix for any Global Navigation Satellite System","type":"object","properties":{{"timestamp":{TIME},"frame_id":{{"type":"string"}},"latitude":{{"type":"number","description":"degrees"}},"longitude":{{"type":"number","description":"degrees"}},"altitude":{{"type":"number","description":"metres above the WGS 84 ellipsoid"}},"position_covariance":{{"type":"array","items":{{"type":"number"}},"minItems":9,"maxItems":9,"description":"m^2, east-north-up, row-major"}},"position_covariance_type":{{"type":"integer","description":"0 UNKNOWN, 1 APPROXIMATED, 2 DIAGONAL_KNOWN, 3 KNOWN"}}}},"required":["timestamp","frame_id","latitude","longitude","altitude","position_covariance","position_covariance_type"]}}"#
        )
    }

    /// `position_covariance_type` of a [`LocationFix`] whose covariance diagonal is known.
    pub const COVARIANCE_DIAGONAL_KNOWN: u8 = 2;
    /// `position_covariance_type` of a [`LocationFix`] without a covariance.
    pub const COVARIANCE_UNKNOWN: u8 = 0;

    /// `foxglove.LocationFix`: a position on the WGS 84 ellipsoid (Foxglove's Map panel).
    #[derive(Clone, Debug, Serialize)]
    pub struct LocationFix<'a> {
        /// Time.
        pub timestamp: Time,
        /// Frame.
        pub frame_id: &'a str,
        /// Latitude, degrees.
        pub latitude: f64,
        /// Longitude, degrees.
        pub longitude: f64,
        /// Height above the ellipsoid, m.
        pub altitude: f64,
        /// Position covariance, m², east-north-up axes, row-major.
        pub position_covariance: [f64; 9],
        /// [`COVARIANCE_DIAGONAL_KNOWN`] or [`COVARIANCE_UNKNOWN`].
        pub position_covariance_type: u8,
    }

    /// A time stamp.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
    pub struct Time {
        /// Seconds.
        pub sec: u64,
        /// Nanoseconds.
        pub nsec: u32,
    }

    impl Time {
        /// From nanoseconds.
        pub fn from_ns(t_ns: u64) -> Self {
            Time {
                sec: t_ns / 1_000_000_000,
                nsec: (t_ns % 1_000_000_000) as u32,
            }
        }
    }

    /// `foxglove.RawImage` (`data` base64).
    #[derive(Clone, Debug, Serialize)]
    pub struct RawImage<'a> {
        /// Time.
        pub timestamp: Time,
        /// Frame.
        pub frame_id: &'a str,
        /// Columns.
        pub width: u32,
        /// Rows.
        pub height: u32,
        /// `mono8`.
        pub encoding: &'a str,
        /// Bytes per row.
        pub step: u32,
        /// The pixels, base64.
        pub data: &'a str,
    }

    /// An RGBA colour, components 0…1.
    #[derive(Clone, Copy, Debug, PartialEq, Serialize)]
    pub struct Color {
        /// Red.
        pub r: f64,
        /// Green.
        pub g: f64,
        /// Blue.
        pub b: f64,
        /// Alpha.
        pub a: f64,
    }

    /// An image point, px.
    #[derive(Clone, Copy, Debug, PartialEq, Serialize)]
    pub struct Point2 {
        /// Column, px.
        pub x: f64,
        /// Row, px.
        pub y: f64,
    }

    /// `foxglove.PointsAnnotation`.
    #[derive(Clone, Debug, Serialize)]
    pub struct PointsAnnotation {
        /// Time.
        pub timestamp: Time,
        /// 3 = LINE_STRIP.
        #[serde(rename = "type")]
        pub kind: u8,
        /// The polyline.
        pub points: Vec<Point2>,
        /// Line colour.
        pub outline_color: Color,
        /// Per-point colours (empty: `outline_color`).
        pub outline_colors: Vec<Color>,
        /// Fill colour (unused for a line strip).
        pub fill_color: Color,
        /// Line width, px.
        pub thickness: f64,
    }

    /// `foxglove.ImageAnnotations` (no circles or texts).
    #[derive(Clone, Debug, Default, Serialize)]
    pub struct ImageAnnotations {
        /// Circles (none).
        pub circles: Vec<serde_json::Value>,
        /// Polylines.
        pub points: Vec<PointsAnnotation>,
        /// Texts (none).
        pub texts: Vec<serde_json::Value>,
    }

    /// Foxglove's `PointsAnnotation` type for a polyline.
    pub const LINE_STRIP: u8 = 3;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_append_writes_the_rfc_4648_text_of_base64_into() {
        // RFC 4648 section 10's vectors.
        for (raw, text) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            let mut out = b"x".to_vec();
            base64_append(raw.as_bytes(), &mut out);
            assert_eq!(out, format!("x{text}").as_bytes());
        }
        let bytes: Vec<u8> = (0..1000u32).map(|k| (k * 7919 % 256) as u8).collect();
        for len in [998, 999, 1000] {
            let (mut a, mut b) = (String::new(), Vec::new());
            base64_into(&bytes[..len], &mut a);
            base64_append(&bytes[..len], &mut b);
            assert_eq!(a.as_bytes(), &b[..]);
        }
    }
}
