//! Reading a recording back: the wire payloads of a topic, checked against this build's wire
//! version, for `primm replay` and for tests.

use crate::raw::{read_payload, zeroed_box, RawPayloadError, WirePayload};
use crate::topics::{Topic, WIRE_ENCODING};
use primm_wire::WIRE_VERSION;
use std::path::{Path, PathBuf};

/// The first bytes of every MCAP file.
const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// Why a recording could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ReadRecordingError {
    /// The file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Open {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The file does not start like an MCAP file.
    #[error("{} is not an MCAP file (it does not start with the MCAP magic bytes)", path.display())]
    NotMcap {
        /// The file.
        path: PathBuf,
    },
    /// The file is cut short or damaged.
    #[error("{} is truncated or damaged after {messages} messages: {source} (`mcap recover` rebuilds what is readable)", path.display())]
    Damaged {
        /// The file.
        path: PathBuf,
        /// Messages read before the damage.
        messages: usize,
        /// The reader's error.
        source: mcap::McapError,
    },
    /// The topic's channel is not primm's wire format of this build.
    #[error("{}: topic {topic} holds {found}, and this build reads primm wire version {WIRE_VERSION}", path.display())]
    WireVersion {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: &'static str,
        /// What the channel says it holds.
        found: String,
    },
    /// A message is not a valid payload.
    #[error("{}: message {index} of {topic}: {source}", path.display())]
    Payload {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: &'static str,
        /// The message's index in the topic.
        index: usize,
        /// What is wrong with it.
        source: RawPayloadError,
    },
}

/// One message of a topic.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordedMessage {
    /// Log time, ns.
    pub log_time_ns: u64,
    /// Publish time, ns.
    pub publish_time_ns: u64,
    /// The message bytes.
    pub data: Vec<u8>,
}

/// Every message of `topic` in `path`, in file order.
pub fn read_topic(path: &Path, topic: Topic) -> Result<Vec<RecordedMessage>, ReadRecordingError> {
    let bytes =
        std::fs::read(path).map_err(|source| ReadRecordingError::Open { path: path.to_owned(), source })?;
    if !bytes.starts_with(MCAP_MAGIC) {
        return Err(ReadRecordingError::NotMcap { path: path.to_owned() });
    }
    let damaged =
        |messages: usize, source| ReadRecordingError::Damaged { path: path.to_owned(), messages, source };
    let mut messages = Vec::new();
    let stream = mcap::MessageStream::new(&bytes).map_err(|source| damaged(0, source))?;
    for (read, message) in stream.enumerate() {
        let message = message.map_err(|source| damaged(read, source))?;
        if message.channel.topic != topic.name() {
            continue;
        }
        if topic.message_encoding() == WIRE_ENCODING {
            check_wire_channel(path, topic, &message.channel)?;
        }
        messages.push(RecordedMessage {
            log_time_ns: message.log_time,
            publish_time_ns: message.publish_time,
            data: message.data.into_owned(),
        });
    }
    Ok(messages)
}

/// Checks that a channel holds primm wire payloads of this build's version.
fn check_wire_channel(
    path: &Path,
    topic: Topic,
    channel: &mcap::Channel<'_>,
) -> Result<(), ReadRecordingError> {
    let version = channel.metadata.get("wire_version");
    if channel.message_encoding == WIRE_ENCODING && version.is_some_and(|v| *v == WIRE_VERSION.to_string()) {
        return Ok(());
    }
    let found = match version {
        Some(version) => format!("primm wire version {version}"),
        None => format!("messages encoded as '{}'", channel.message_encoding),
    };
    Err(ReadRecordingError::WireVersion { path: path.to_owned(), topic: topic.name(), found })
}

/// The wire payloads of `topic` as boxed frames of type `T`.
pub fn read_frames<T: WirePayload>(path: &Path, topic: Topic) -> Result<Vec<Box<T>>, ReadRecordingError> {
    read_topic(path, topic)?
        .iter()
        .enumerate()
        .map(|(index, message)| {
            let mut frame = zeroed_box::<T>();
            read_payload(&message.data, &mut *frame).map_err(|source| ReadRecordingError::Payload {
                path: path.to_owned(),
                topic: topic.name(),
                index,
                source,
            })?;
            Ok(frame)
        })
        .collect()
}
