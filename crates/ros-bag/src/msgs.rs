//! The ROS 2 messages read from bags, decoded from CDR without copying their payloads
//! (layouts from `sensor_msgs/msg/{Image,CompressedImage,Imu}.msg` and `std_msgs/msg/Header`),
//! and their encoders (tests, round trips).

use crate::BagError;
use crate::cdr::{CdrReader, CdrWriter};

/// ROS schema name of an uncompressed image.
pub const IMAGE: &str = "sensor_msgs/msg/Image";
/// ROS schema name of a compressed image.
pub const COMPRESSED_IMAGE: &str = "sensor_msgs/msg/CompressedImage";
/// ROS schema name of an IMU sample.
pub const IMU: &str = "sensor_msgs/msg/Imu";

/// `std_msgs/Header`: the time stamp and the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header<'a> {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds (0..1e9).
    pub nanosec: u32,
    /// Coordinate frame.
    pub frame_id: &'a str,
}

impl Header<'_> {
    /// The stamp in seconds.
    pub fn t_s(&self) -> f64 {
        f64::from(self.sec) + 1e-9 * f64::from(self.nanosec)
    }

    fn read<'a>(r: &mut CdrReader<'a>) -> Result<Header<'a>, BagError> {
        Ok(Header {
            sec: r.i32("header.stamp.sec")?,
            nanosec: r.u32("header.stamp.nanosec")?,
            frame_id: r.string("header.frame_id")?,
        })
    }

    fn write(&self, w: &mut CdrWriter) {
        w.i32(self.sec).u32(self.nanosec).string(self.frame_id);
    }
}

/// `sensor_msgs/msg/Image`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Image<'a> {
    /// Header.
    pub header: Header<'a>,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// Pixel encoding (`mono8`, `rgb8`, `bgr8`, `rgba8`, `bgra8`, `mono16`, …).
    pub encoding: &'a str,
    /// Multi-byte pixels are big endian.
    pub is_bigendian: u8,
    /// Bytes per row.
    pub step: u32,
    /// Pixels, `step × height` bytes.
    pub data: &'a [u8],
}

impl<'a> Image<'a> {
    /// Decodes a CDR message.
    ///
    /// # Errors
    /// [`BagError::Cdr`] naming the field that is cut short or malformed.
    pub fn decode(buf: &'a [u8]) -> Result<Self, BagError> {
        let mut r = CdrReader::new(buf)?;
        Ok(Image {
            header: Header::read(&mut r)?,
            height: r.u32("height")?,
            width: r.u32("width")?,
            encoding: r.string("encoding")?,
            is_bigendian: r.u8("is_bigendian")?,
            step: r.u32("step")?,
            data: r.bytes("data")?,
        })
    }

    /// Encodes as CDR (little endian).
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.header.write(&mut w);
        w.u32(self.height)
            .u32(self.width)
            .string(self.encoding)
            .u8(self.is_bigendian)
            .u32(self.step)
            .bytes(self.data);
        w.finish()
    }
}

/// `sensor_msgs/msg/CompressedImage`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CompressedImage<'a> {
    /// Header.
    pub header: Header<'a>,
    /// `jpeg`, `png` (possibly with a prefix such as `rgb8; jpeg compressed bgr8`).
    pub format: &'a str,
    /// The compressed image.
    pub data: &'a [u8],
}

impl<'a> CompressedImage<'a> {
    /// Decodes a CDR message.
    ///
    /// # Errors
    /// [`BagError::Cdr`].
    pub fn decode(buf: &'a [u8]) -> Result<Self, BagError> {
        let mut r = CdrReader::new(buf)?;
        Ok(CompressedImage {
            header: Header::read(&mut r)?,
            format: r.string("format")?,
            data: r.bytes("data")?,
        })
    }

    /// Encodes as CDR (little endian).
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.header.write(&mut w);
        w.string(self.format).bytes(self.data);
        w.finish()
    }
}

/// `sensor_msgs/msg/Imu`, the parts a strapdown INS uses (ROS body axes: FLU).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Imu<'a> {
    /// Header.
    pub header: Header<'a>,
    /// Angular rate, rad/s, body FLU.
    pub angular_velocity_radps: [f64; 3],
    /// Specific force ("linear acceleration", gravity included), m/s², body FLU.
    pub linear_acceleration_mps2: [f64; 3],
}

impl<'a> Imu<'a> {
    /// Decodes a CDR message (the orientation and the covariances are read past).
    ///
    /// # Errors
    /// [`BagError::Cdr`].
    pub fn decode(buf: &'a [u8]) -> Result<Self, BagError> {
        let mut r = CdrReader::new(buf)?;
        let header = Header::read(&mut r)?;
        for _ in 0..4 + 9 {
            r.f64("orientation")?;
        }
        let mut w = [0.0; 3];
        for v in &mut w {
            *v = r.f64("angular_velocity")?;
        }
        for _ in 0..9 {
            r.f64("angular_velocity_covariance")?;
        }
        let mut a = [0.0; 3];
        for v in &mut a {
            *v = r.f64("linear_acceleration")?;
        }
        for _ in 0..9 {
            r.f64("linear_acceleration_covariance")?;
        }
        Ok(Imu {
            header,
            angular_velocity_radps: w,
            linear_acceleration_mps2: a,
        })
    }

    /// Encodes as CDR (little endian; orientation unknown: zeros with `covariance[0] = −1`, as
    /// REP 145 says).
    pub fn encode(&self) -> Vec<u8> {
        let mut w = CdrWriter::new();
        self.header.write(&mut w);
        for _ in 0..4 {
            w.f64(0.0);
        }
        w.f64(-1.0);
        for _ in 0..8 {
            w.f64(0.0);
        }
        for v in self.angular_velocity_radps {
            w.f64(v);
        }
        for _ in 0..9 {
            w.f64(0.0);
        }
        for v in self.linear_acceleration_mps2 {
            w.f64(v);
        }
        for _ in 0..9 {
            w.f64(0.0);
        }
        w.finish()
    }

    /// The sample in the FRD body axes of `ins-sd-filter` (x forward, y right, z down) from ROS's
    /// FLU (REP 103: x forward, y left, z up): (x, −y, −z) for both vectors. Returns (specific
    /// force m/s², angular rate rad/s).
    pub fn frd(&self) -> ([f64; 3], [f64; 3]) {
        let [ax, ay, az] = self.linear_acceleration_mps2;
        let [wx, wy, wz] = self.angular_velocity_radps;
        ([ax, -ay, -az], [wx, -wy, -wz])
    }
}
