//! The crate's one error type.

/// Everything that can go wrong reading or writing a bag; each variant names the file, topic,
/// message or byte offset concerned.
#[derive(Debug, thiserror::Error)]
pub enum BagError {
    /// The file could not be opened, read or written.
    #[error("{path}")]
    Io {
        /// The file.
        path: String,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },
    /// The MCAP container is damaged (truncated, bad CRC, bad record) or could not be written.
    #[error("{path}: MCAP")]
    Mcap {
        /// The file.
        path: String,
        /// The MCAP library's error.
        #[source]
        source: mcap::McapError,
    },
    /// A message's CDR payload is malformed.
    #[error("CDR at byte {offset}: {what}")]
    Cdr {
        /// Byte offset in the message.
        offset: usize,
        /// What is wrong.
        what: String,
    },
    /// A message of a topic could not be decoded (its CDR error, with where).
    #[error("{path}: topic {topic}, message at t = {log_time_ns} ns")]
    Message {
        /// The file.
        path: String,
        /// The topic.
        topic: String,
        /// The message's log time, ns.
        log_time_ns: u64,
        /// The decoding error.
        #[source]
        source: Box<BagError>,
    },
    /// No topic of the wanted types, or several and none chosen, or the chosen one is missing
    /// or of another type.
    #[error("{path}: {problem}; topics: {topics}")]
    Topic {
        /// The file.
        path: String,
        /// What is wrong.
        problem: String,
        /// Every topic with its schema, for the user to choose from.
        topics: String,
    },
    /// A topic's messages are not CDR (`message_encoding` other than `cdr`).
    #[error("{path}: topic {topic} has message encoding `{encoding}`, not cdr")]
    Encoding {
        /// The file.
        path: String,
        /// The topic.
        topic: String,
        /// Its message encoding.
        encoding: String,
    },
    /// A JSON message could not be serialised.
    #[error("{path}: topic {topic}")]
    Json {
        /// The file.
        path: String,
        /// The topic.
        topic: String,
        /// serde_json's error.
        #[source]
        source: serde_json::Error,
    },
}

impl BagError {
    pub(crate) fn cdr(offset: usize, what: impl Into<String>) -> Self {
        BagError::Cdr {
            offset,
            what: what.into(),
        }
    }
}
