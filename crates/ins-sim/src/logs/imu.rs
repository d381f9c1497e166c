//! The IMU samples of a replay, from a CSV log (increments or rates, by its header) or from a
//! ROS 2 bag's `sensor_msgs/msg/Imu` topic (rates; ROS's FLU body axes turned into the filter's
//! FRD, `ros_bag::msgs::Imu::frd`; the time is the message header's stamp).

use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use ros_bag::bag::{TopicReader, choose_topic, topics};
use ros_bag::msgs::{IMU, Imu};

use super::read::CsvReader;
use super::{IMU_HEADER, IMU_RATES_HEADER};
use crate::SimError;

/// One IMU sample: time, and (specific force, angular rate) for rates or (Δv, Δθ) for
/// increments, body FRD; `line` is the CSV line or the bag message's number (1-based).
#[derive(Clone, Copy, Debug)]
pub(super) struct ImuRecord {
    pub(super) t_s: f64,
    pub(super) a: Vector3<f64>,
    pub(super) b: Vector3<f64>,
    pub(super) line: usize,
}

pub(super) enum ImuStream {
    Csv {
        reader: CsvReader,
        rates: bool,
    },
    Bag {
        reader: Box<TopicReader>,
        path: PathBuf,
        count: usize,
    },
}

fn bag_err(source: ros_bag::BagError) -> SimError {
    SimError::Bag { source }
}

/// True when `path` is a ROS 2 bag (`.mcap`).
pub fn is_bag(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
}

impl ImuStream {
    /// Opens a CSV log, or a bag's IMU topic (`topic`, or its only `sensor_msgs/msg/Imu`).
    pub(super) fn open(path: &Path, topic: Option<&str>) -> Result<Self, SimError> {
        if is_bag(path) {
            let name = path.display().to_string();
            let all = topics(&name).map_err(bag_err)?;
            let chosen = choose_topic(&name, &all, topic, &[IMU], "IMU").map_err(bag_err)?;
            return Ok(ImuStream::Bag {
                reader: Box::new(TopicReader::open(&name, chosen).map_err(bag_err)?),
                path: path.to_path_buf(),
                count: 0,
            });
        }
        let (reader, which) = CsvReader::open_any(path, &[IMU_HEADER, IMU_RATES_HEADER])?;
        Ok(ImuStream::Csv {
            reader,
            rates: which == 1,
        })
    }

    /// True when the samples are rates (else increments).
    pub(super) fn rates(&self) -> bool {
        match self {
            ImuStream::Csv { rates, .. } => *rates,
            ImuStream::Bag { .. } => true,
        }
    }

    /// The file.
    pub(super) fn path(&self) -> PathBuf {
        match self {
            ImuStream::Csv { reader, .. } => reader.path.clone(),
            ImuStream::Bag { path, .. } => path.clone(),
        }
    }

    /// An error at `line` (CSV line, or bag message number).
    pub(super) fn parse_err(&self, line: usize, column: usize, message: String) -> SimError {
        SimError::LogParse {
            path: self.path(),
            line,
            column,
            message,
        }
    }

    pub(super) fn next(&mut self) -> Result<Option<ImuRecord>, SimError> {
        match self {
            ImuStream::Csv { reader, rates } => {
                let Some(rec) = reader.next()? else {
                    return Ok(None);
                };
                let names: Vec<&str> = if *rates { IMU_RATES_HEADER } else { IMU_HEADER }
                    .split(',')
                    .collect();
                let mut v = [0.0; 7];
                for (i, x) in v.iter_mut().enumerate() {
                    *x = reader.f64(&rec, i, names[i])?;
                }
                let (a, b) = if *rates {
                    (
                        Vector3::new(v[4], v[5], v[6]),
                        Vector3::new(v[1], v[2], v[3]),
                    )
                } else {
                    (
                        Vector3::new(v[1], v[2], v[3]),
                        Vector3::new(v[4], v[5], v[6]),
                    )
                };
                Ok(Some(ImuRecord {
                    t_s: v[0],
                    a,
                    b,
                    line: rec.line,
                }))
            }
            ImuStream::Bag {
                reader,
                path,
                count,
            } => {
                let Some(msg) = reader.next_message().map_err(bag_err)? else {
                    return Ok(None);
                };
                *count += 1;
                let log_time_ns = msg.log_time_ns;
                let decoded = Imu::decode(msg.data).map(|imu| (imu.header.t_s(), imu.frd()));
                let (t_s, (f, w)) = decoded.map_err(|source| SimError::Bag {
                    source: ros_bag::BagError::Message {
                        path: path.display().to_string(),
                        topic: reader.topic().topic.clone(),
                        log_time_ns,
                        source: Box::new(source),
                    },
                })?;
                Ok(Some(ImuRecord {
                    t_s,
                    a: Vector3::from(f),
                    b: Vector3::from(w),
                    line: *count,
                }))
            }
        }
    }
}
