//! # ros-bag — ROS 2 bags (MCAP) in, JSON channels out
//!
//! What a robot's recordings need to reach the lane tracker and the INS/SD filter, and what
//! their results need to reach Foxglove:
//!
//! * [`cdr`]: the OMG CDR encoding of ROS 2 messages (reader and writer);
//! * [`msgs`]: `sensor_msgs/msg/Image`, `CompressedImage` and `Imu` decoded without copying
//!   their payloads (and encoded, for tests and round trips); `Imu::frd` turns ROS's FLU body
//!   axes into the FRD axes of the INS;
//! * [`bag`]: a bag's topics, choosing one by type, and streaming its messages (the maintained
//!   `mcap` crate reads the container: chunks, zstd/lz4, CRCs);
//! * [`out`]: an MCAP writer of JSON-encoded channels with JSON schemas (Foxglove's
//!   `foxglove.RawImage` and `foxglove.ImageAnnotations`, and our own lane messages).
//!
//! No lane or INS type appears here; `lane-io` and `ins-sim` build on it.

pub mod bag;
pub mod cdr;
mod error;
pub mod msgs;
pub mod out;

pub use error::BagError;
