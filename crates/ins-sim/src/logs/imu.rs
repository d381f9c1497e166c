//! The IMU samples of a replay, from a CSV log (increments or rates, by its header), from a
//! ROS 2 bag's `sensor_msgs/msg/Imu` topic (rates; ROS's FLU body axes turned into the filter's
//! FRD, `ros_bag::msgs::Imu::frd`; the time is the message header's stamp), or from an
//! EuRoC/ASL folder (rates; nanosecond stamps; the IMU's axes rotated into the body's,
//! [`super::asl`]).
//!
//! A replay opens its log once, as an [`ImuLog`]: what is read before the replay proper (the
//! nominal step, [`ImuLog::nominal_step_s`]; a static alignment, [`super::align_at_rest`]) is
//! read ahead and kept, and the replay takes those samples first, then reads on.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Vector3};
use ros_bag::bag::{TopicReader, choose_topic, topics};
use ros_bag::msgs::{IMU, Imu};

use super::asl::{ASL_IMU_NAMES, asl_body_from_imu, asl_imu_file, next_imu, open_asl};
use super::csv::CsvReader;
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

/// The open file: CSV, or a bag's IMU topic.
enum ImuStream {
    Csv {
        reader: CsvReader,
        rates: bool,
    },
    Bag {
        reader: Box<TopicReader>,
        path: PathBuf,
        count: usize,
    },
    /// An ASL `imu0/data.csv`: rates, nanosecond stamps, rotated into the body axes.
    Asl {
        reader: CsvReader,
        body_from_imu: Matrix3<f64>,
        prev_ns: Option<u64>,
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
    /// Opens a CSV log, a bag's IMU topic (`topic`, or its only `sensor_msgs/msg/Imu`), or an
    /// ASL folder's IMU (rotated by `body_from_imu`, else by its `sensor.yaml`).
    fn open(
        path: &Path,
        topic: Option<&str>,
        body_from_imu: Option<Matrix3<f64>>,
    ) -> Result<Self, SimError> {
        if let Some(file) = asl_imu_file(path) {
            let body_from_imu = asl_body_from_imu(&file, body_from_imu)?;
            return Ok(ImuStream::Asl {
                reader: open_asl(&file, &ASL_IMU_NAMES)?,
                body_from_imu,
                prev_ns: None,
            });
        }
        if body_from_imu.is_some() {
            return Err(SimError::invalid(
                "imu_to_body",
                "applies to an EuRoC/ASL folder's IMU only (a CSV log or a bag is in body axes)",
                path,
            ));
        }
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
    fn rates(&self) -> bool {
        match self {
            ImuStream::Csv { rates, .. } => *rates,
            ImuStream::Bag { .. } | ImuStream::Asl { .. } => true,
        }
    }

    fn next(&mut self) -> Result<Option<ImuRecord>, SimError> {
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
            ImuStream::Asl {
                reader,
                body_from_imu,
                prev_ns,
            } => next_imu(reader, body_from_imu, prev_ns),
        }
    }
}

/// An IMU log (CSV, or a bag's IMU topic) read once per replay. It is opened at the first read;
/// samples looked at before the replay ([`ImuLog::nominal_step_s`], [`super::align_at_rest`]) are
/// kept, and the replay takes them first, then reads on: the file is read once, from
/// the start, in order, and its errors surface where they did when each step read it anew.
pub struct ImuLog {
    path: PathBuf,
    topic: Option<String>,
    body_from_imu: Option<Matrix3<f64>>,
    stream: Option<ImuStream>,
    /// Samples read ahead and not yet taken by [`ImuLog::next`].
    ahead: VecDeque<ImuRecord>,
}

impl std::fmt::Debug for ImuLog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ImuLog")
            .field("path", &self.path)
            .field("topic", &self.topic)
            .field("open", &self.stream.is_some())
            .field("read_ahead", &self.ahead.len())
            .finish()
    }
}

impl ImuLog {
    /// The log at `path` (CSV increments or rates, declared by its header; or a ROS 2 bag,
    /// `.mcap`, with its `sensor_msgs/msg/Imu` `topic`, default: the only one). Nothing is read
    /// yet.
    pub fn new(path: impl Into<PathBuf>, topic: Option<String>) -> Self {
        Self {
            path: path.into(),
            topic,
            body_from_imu: None,
            stream: None,
            ahead: VecDeque::new(),
        }
    }

    /// For an EuRoC/ASL folder: the rotation IMU axes → body axes, C_B^S (default: its
    /// `sensor.yaml`'s `T_BS`); refused at the first read for any other log.
    pub fn with_body_from_imu(mut self, body_from_imu: Option<Matrix3<f64>>) -> Self {
        self.body_from_imu = body_from_imu;
        self
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn stream(&mut self) -> Result<&mut ImuStream, SimError> {
        let stream = match self.stream.take() {
            Some(s) => s,
            None => ImuStream::open(&self.path, self.topic.as_deref(), self.body_from_imu)?,
        };
        Ok(self.stream.insert(stream))
    }

    /// True when the samples are rates (else increments).
    ///
    /// # Errors
    /// Opening the log: [`SimError::LogIo`], [`SimError::LogParse`] (header), [`SimError::Bag`].
    pub(super) fn rates(&mut self) -> Result<bool, SimError> {
        Ok(self.stream()?.rates())
    }

    /// The sample `i` places after the next one [`ImuLog::next`] would return (`None` past the
    /// end), read ahead and kept.
    pub(super) fn peek(&mut self, i: usize) -> Result<Option<ImuRecord>, SimError> {
        while self.ahead.len() <= i {
            let Some(rec) = self.stream()?.next()? else {
                return Ok(None);
            };
            self.ahead.push_back(rec);
        }
        Ok(self.ahead.get(i).copied())
    }

    /// The next sample: one read ahead if any, else the next in the file.
    pub(super) fn next(&mut self) -> Result<Option<ImuRecord>, SimError> {
        match self.ahead.pop_front() {
            Some(rec) => Ok(Some(rec)),
            None => self.stream()?.next(),
        }
    }

    /// An error at `line` (CSV line, or bag message number).
    pub(super) fn parse_err(&self, line: usize, column: usize, message: String) -> SimError {
        SimError::LogParse {
            path: self.path.clone(),
            line,
            column,
            message,
        }
    }

    /// The nominal step: the median interval of the first 200 samples, s (the samples are kept
    /// for the replay).
    ///
    /// # Errors
    /// [`SimError::LogIo`], [`SimError::LogParse`] for a bad header or time field, or fewer than
    /// two samples.
    pub fn nominal_step_s(&mut self) -> Result<f64, SimError> {
        let mut times = Vec::with_capacity(201);
        let mut line = 1;
        while times.len() < 201 {
            let Some(rec) = self.peek(times.len())? else {
                break;
            };
            times.push(rec.t_s);
            line = rec.line;
        }
        let mut dts: Vec<f64> = times
            .windows(2)
            .map(|w| w[1] - w[0])
            .filter(|d| *d > 0.0)
            .collect();
        if dts.is_empty() {
            return Err(self.parse_err(
                line,
                1,
                "fewer than two increasing IMU time stamps: no sample rate".into(),
            ));
        }
        dts.sort_by(f64::total_cmp);
        Ok(dts[dts.len() / 2])
    }
}

/// The nominal step of an IMU log (either header, or a bag's IMU `topic`): the median interval
/// of its first 200 samples, s ([`ImuLog::nominal_step_s`] on a log of its own).
///
/// # Errors
/// [`SimError::LogIo`], [`SimError::LogParse`] for a bad header or time field, or fewer than two
/// samples.
pub fn imu_nominal_step_s(path: &Path, topic: Option<&str>) -> Result<f64, SimError> {
    ImuLog::new(path, topic.map(str::to_owned)).nominal_step_s()
}
