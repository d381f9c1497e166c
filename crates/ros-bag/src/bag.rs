//! Reading a bag: its topics (from the summary, or by a pass over the file when it has none)
//! and the messages of one topic in file order, streamed ([`TopicReader`]).

use std::fs::File;
use std::io::{BufReader, Seek};

use mcap::sans_io::summary_reader::{SummaryReadEvent, SummaryReader, SummaryReaderOptions};

use crate::BagError;

/// Reading options: each chunk's CRC is checked **before** any of its messages is delivered, so
/// a damaged byte in a chunk is an error, never a wrong pixel. (Checking it after, as the
/// `validate_chunk_crcs` option does, would hand out the chunk's altered messages first; the
/// data-section CRC, which would hash every byte a second time, is not checked.)
///
/// Records are also bounded ([`record_limit`]): a damaged length field must be an error, not an
/// attempt to allocate exabytes (which aborts the process).
fn checked(file_len: u64) -> mcap::sans_io::LinearReaderOptions {
    mcap::sans_io::LinearReaderOptions::default()
        .with_prevalidate_chunk_crcs(true)
        .with_record_length_limit(record_limit(file_len))
}

/// The largest record, compressed or decompressed chunk the reader accepts in a file of
/// `file_len` bytes: 256 × the file (chunks of camera frames compress far less than that), never
/// below 64 MiB (a few 4K RGBA frames) nor above 1 GiB.
pub fn record_limit(file_len: u64) -> usize {
    const MIB: u64 = 1 << 20;
    usize::try_from(file_len.saturating_mul(256).clamp(64 * MIB, 1024 * MIB)).unwrap_or(usize::MAX)
}

fn file_len(file: &File, path: &str) -> Result<u64, BagError> {
    Ok(file.metadata().map_err(io(path))?.len())
}

/// One topic of a bag.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TopicInfo {
    /// The topic name.
    pub topic: String,
    /// The schema name (e.g. `sensor_msgs/msg/Image`; empty without a schema).
    pub schema: String,
    /// The message encoding (`cdr` for ROS 2).
    pub encoding: String,
}

fn io(path: &str) -> impl Fn(std::io::Error) -> BagError + '_ {
    move |source| BagError::Io {
        path: path.to_owned(),
        source,
    }
}

fn mcap_err(path: &str) -> impl Fn(mcap::McapError) -> BagError + '_ {
    move |source| BagError::Mcap {
        path: path.to_owned(),
        source,
    }
}

fn info(c: &mcap::Channel<'_>) -> TopicInfo {
    TopicInfo {
        topic: c.topic.clone(),
        schema: c
            .schema
            .as_ref()
            .map(|s| s.name.clone())
            .unwrap_or_default(),
        encoding: c.message_encoding.clone(),
    }
}

/// The summary section, `None` when the file has none or it cannot be read (no footer: a
/// truncated file).
fn summary(path: &str) -> Result<Option<mcap::Summary>, BagError> {
    let mut file = File::open(path).map_err(io(path))?;
    let len = file_len(&file, path)?;
    let mut reader = SummaryReader::new_with_options(
        SummaryReaderOptions::default()
            .with_file_size(len)
            .with_record_length_limit(record_limit(len)),
    );
    while let Some(event) = reader.next_event() {
        let Ok(event) = event else {
            return Ok(None);
        };
        match event {
            SummaryReadEvent::ReadRequest(need) => {
                let n = std::io::Read::read(&mut file, reader.insert(need)).map_err(io(path))?;
                reader.notify_read(n);
            }
            SummaryReadEvent::SeekRequest(to) => {
                reader.notify_seeked(file.seek(to).map_err(io(path))?);
            }
        }
    }
    Ok(reader.finish())
}

/// The topics of the bag at `path`, sorted by name.
///
/// # Errors
/// [`BagError::Io`], [`BagError::Mcap`] for a damaged file.
pub fn topics(path: &str) -> Result<Vec<TopicInfo>, BagError> {
    let mut out: Vec<TopicInfo> = match summary(path)? {
        Some(summary) => summary.channels.values().map(|c| info(c)).collect(),
        None => {
            // No summary (a bag cut short while recording): the channels of its messages, up to
            // the damage (reading stops with an error there; the topics before it are usable).
            let file = File::open(path).map_err(io(path))?;
            let len = file_len(&file, path)?;
            let mut seen: Vec<TopicInfo> = Vec::new();
            for m in mcap::io::MessageReader::new_with_options(BufReader::new(file), checked(len)) {
                let m = match m {
                    Ok(m) => m,
                    Err(e) if seen.is_empty() => return Err(mcap_err(path)(e)),
                    Err(_) => break,
                };
                if !seen.iter().any(|t| t.topic == m.channel.topic) {
                    seen.push(info(&m.channel));
                }
            }
            seen
        }
    };
    out.sort_by(|a, b| a.topic.cmp(&b.topic));
    out.dedup();
    Ok(out)
}

/// `topics` as one line for errors: `/a (sensor_msgs/msg/Image), /b (…)`.
pub fn list(topics: &[TopicInfo]) -> String {
    if topics.is_empty() {
        return "(none)".to_owned();
    }
    topics
        .iter()
        .map(|t| {
            format!(
                "{} ({})",
                t.topic,
                if t.schema.is_empty() {
                    "no schema"
                } else {
                    &t.schema
                }
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Chooses the topic to read: `wanted` if given (it must exist with one of `schemas`), else the
/// only topic with one of `schemas`.
///
/// # Errors
/// [`BagError::Topic`] listing every topic when there is no such topic, or several and none was
/// chosen, or the chosen one is missing or of another type; [`BagError::Encoding`] when it is not
/// CDR.
pub fn choose_topic(
    path: &str,
    topics: &[TopicInfo],
    wanted: Option<&str>,
    schemas: &[&str],
    what: &str,
) -> Result<TopicInfo, BagError> {
    let fail = |problem: String| BagError::Topic {
        path: path.to_owned(),
        problem,
        topics: list(topics),
    };
    let chosen = match wanted {
        Some(name) => {
            let Some(t) = topics.iter().find(|t| t.topic == name) else {
                return Err(fail(format!("no topic {name}")));
            };
            if !schemas.contains(&t.schema.as_str()) {
                return Err(fail(format!(
                    "topic {name} is {}, not {}",
                    t.schema,
                    schemas.join(" or ")
                )));
            }
            t.clone()
        }
        None => {
            let of_kind: Vec<&TopicInfo> = topics
                .iter()
                .filter(|t| schemas.contains(&t.schema.as_str()))
                .collect();
            match of_kind.as_slice() {
                [one] => (*one).clone(),
                [] => return Err(fail(format!("no {what} topic ({})", schemas.join(", ")))),
                _ => {
                    return Err(fail(format!(
                        "{} {what} topics: choose one with --topic",
                        of_kind.len()
                    )));
                }
            }
        }
    };
    if chosen.encoding != "cdr" {
        return Err(BagError::Encoding {
            path: path.to_owned(),
            topic: chosen.topic,
            encoding: chosen.encoding,
        });
    }
    Ok(chosen)
}

/// One message of the topic read: its payload (borrowed from the reader until the next call)
/// and times.
#[derive(Debug)]
pub struct BagMessage<'a> {
    /// The schema name of its channel.
    pub schema: &'a str,
    /// Log time, ns.
    pub log_time_ns: u64,
    /// The CDR payload.
    pub data: &'a [u8],
}

/// The messages of one topic in file order, streamed from the file.
///
/// Reads the records with the `mcap` crate's sans-I/O linear reader and keeps only what the
/// topic needs: the ids of its channels (from the channel records) and one payload buffer that
/// is reused, so a frame costs no allocation once the buffers have grown to the largest chunk and
/// message (the crate's own `MessageReader` copies every payload into a new vector).
pub struct TopicReader {
    path: String,
    topic: TopicInfo,
    file: File,
    reader: mcap::sans_io::LinearReader,
    /// Every channel id seen, and whether it is the topic's.
    channels: Vec<(u16, bool)>,
    payload: Vec<u8>,
    done: bool,
}

impl std::fmt::Debug for TopicReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TopicReader")
            .field("path", &self.path)
            .field("topic", &self.topic)
            .finish()
    }
}

impl TopicReader {
    /// Opens `path` for the messages of `topic` (from [`choose_topic`]).
    ///
    /// # Errors
    /// [`BagError::Io`].
    pub fn open(path: &str, topic: TopicInfo) -> Result<Self, BagError> {
        let file = File::open(path).map_err(io(path))?;
        let len = file_len(&file, path)?;
        Ok(Self {
            path: path.to_owned(),
            topic,
            file,
            reader: mcap::sans_io::LinearReader::new_with_options(checked(len)),
            channels: Vec::new(),
            payload: Vec::new(),
            done: false,
        })
    }

    /// The file.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// The topic read.
    pub fn topic(&self) -> &TopicInfo {
        &self.topic
    }

    /// The next message of the topic, `None` at the end of the data section.
    ///
    /// # Errors
    /// [`BagError::Io`], [`BagError::Mcap`] for a damaged file (after the last good message; a
    /// message on a channel no channel record announced is such damage).
    pub fn next_message(&mut self) -> Result<Option<BagMessage<'_>>, BagError> {
        if self.done {
            return Ok(None);
        }
        let path = self.path.as_str();
        while let Some(event) = self.reader.next_event() {
            let event = match event {
                Ok(e) => e,
                Err(e) => {
                    self.done = true;
                    return Err(mcap_err(path)(e));
                }
            };
            let (opcode, data) = match event {
                mcap::sans_io::LinearReadEvent::ReadRequest(need) => {
                    let n = loop {
                        match std::io::Read::read(&mut self.file, self.reader.insert(need)) {
                            Ok(n) => break n,
                            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                            Err(e) => {
                                self.done = true;
                                return Err(io(path)(e));
                            }
                        }
                    };
                    self.reader.notify_read(n);
                    continue;
                }
                mcap::sans_io::LinearReadEvent::Record { opcode, data } => (opcode, data),
            };
            match opcode {
                mcap::records::op::DATA_END => {
                    // The summary after it repeats channels and holds no message.
                    self.done = true;
                    return Ok(None);
                }
                mcap::records::op::CHANNEL | mcap::records::op::MESSAGE => {}
                _ => continue,
            }
            let record = match mcap::parse_record(opcode, data) {
                Ok(r) => r,
                Err(e) => {
                    self.done = true;
                    return Err(mcap_err(path)(e));
                }
            };
            match record {
                mcap::records::Record::Channel(c)
                    if !self.channels.iter().any(|(id, _)| *id == c.id) =>
                {
                    self.channels.push((c.id, c.topic == self.topic.topic));
                }
                mcap::records::Record::Message { header, data } => {
                    match self
                        .channels
                        .iter()
                        .find(|(id, _)| *id == header.channel_id)
                    {
                        Some((_, true)) => {
                            self.payload.clear();
                            self.payload.extend_from_slice(&data);
                            return Ok(Some(BagMessage {
                                schema: &self.topic.schema,
                                log_time_ns: header.log_time,
                                data: &self.payload,
                            }));
                        }
                        Some((_, false)) => {}
                        None => {
                            self.done = true;
                            return Err(mcap_err(path)(mcap::McapError::UnknownChannel(
                                header.sequence,
                                header.channel_id,
                            )));
                        }
                    }
                }
                _ => {}
            }
        }
        self.done = true;
        Ok(None)
    }
}
