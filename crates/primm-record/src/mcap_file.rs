//! [`McapFile`]: messages into an MCAP file, chunked and zstd-compressed, with the summary and
//! indexes written at the end.
//!
//! Chunks go to the file as they fill (about every [`CHUNK_BYTES`] of messages), so a recording
//! cut short (the process killed, the disk full) keeps every complete chunk: `mcap recover`
//! rebuilds a readable file from it.

use crate::topics::{Message, MessageSink, SinkError, Topic};
use mcap::records::MessageHeader;
use mcap::{Compression, WriteOptions, Writer};
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// Uncompressed bytes of messages per chunk.
pub const CHUNK_BYTES: u64 = 1024 * 1024;

/// Why an MCAP file could not be written.
#[derive(Debug, thiserror::Error)]
pub enum McapFileError {
    /// The file could not be created.
    #[error("cannot create {}: {source}", path.display())]
    Create {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Writing failed (the disk may be full); the chunks written before stay readable with
    /// `mcap recover`.
    #[error("cannot write {}: {} (the part written so far can be read back with `mcap recover`)", path.display(), os_reason(source))]
    Write {
        /// The file.
        path: PathBuf,
        /// The MCAP writer's error.
        source: mcap::McapError,
    },
}

/// What went wrong in a write, with the OS's words where the operating system refused it ("No
/// space left on device"), which the MCAP error alone leaves out.
fn os_reason(error: &mcap::McapError) -> String {
    match error {
        mcap::McapError::Io(io) => io.to_string(),
        other => other.to_string(),
    }
}

/// An MCAP file being written.
pub struct McapFile {
    writer: Writer<BufWriter<File>>,
    path: PathBuf,
    channels: [Option<u16>; Topic::COUNT],
    sequences: [u32; Topic::COUNT],
}

impl std::fmt::Debug for McapFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("McapFile").field("path", &self.path).field("channels", &self.channels).finish()
    }
}

impl McapFile {
    /// Creates (or truncates) `path` and writes the MCAP header.
    pub fn create(path: &Path) -> Result<Self, McapFileError> {
        let file =
            File::create(path).map_err(|source| McapFileError::Create { path: path.to_owned(), source })?;
        let writer = WriteOptions::new()
            .compression(Some(Compression::Zstd))
            .chunk_size(Some(CHUNK_BYTES))
            .profile("")
            .library(format!("primm {}", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::new(file))
            .map_err(|source| McapFileError::Write { path: path.to_owned(), source })?;
        Ok(Self {
            writer,
            path: path.to_owned(),
            channels: [None; Topic::COUNT],
            sequences: [0; Topic::COUNT],
        })
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn failed(&self, source: mcap::McapError) -> McapFileError {
        McapFileError::Write { path: self.path.clone(), source }
    }

    /// The channel of `topic`, added (with its schema) on first use.
    fn channel(&mut self, topic: Topic) -> Result<u16, McapFileError> {
        if let Some(id) = self.channels[topic.index()] {
            return Ok(id);
        }
        let schema = topic.schema();
        let schema_id = self
            .writer
            .add_schema(&schema.name, &schema.encoding, &schema.data)
            .map_err(|e| self.failed(e))?;
        let id = self
            .writer
            .add_channel(schema_id, topic.name(), topic.message_encoding(), &topic.metadata())
            .map_err(|e| self.failed(e))?;
        self.channels[topic.index()] = Some(id);
        Ok(id)
    }

    /// Writes the last chunk, the summary and the indexes, and closes the file.
    pub fn finish(mut self) -> Result<(), McapFileError> {
        self.writer.finish().map_err(|e| self.failed(e))?;
        let path = self.path;
        let mut file = self.writer.into_inner();
        std::io::Write::flush(&mut file).map_err(|e| McapFileError::Write { path, source: e.into() })
    }
}

impl MessageSink for McapFile {
    fn write(&mut self, message: &Message<'_>) -> Result<(), SinkError> {
        let channel_id = self.channel(message.topic)?;
        let sequence = &mut self.sequences[message.topic.index()];
        let header = MessageHeader {
            channel_id,
            sequence: *sequence,
            log_time: message.log_time_ns,
            publish_time: message.publish_time_ns,
        };
        *sequence = sequence.wrapping_add(1);
        self.writer.write_to_known_channel(&header, message.data).map_err(|e| self.failed(e))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_messages(file: &mut McapFile, count: u64) {
        // Bytes that do not compress, so that chunks fill at their nominal size either way.
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let data: Vec<u8> = (0..1000)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                state as u8
            })
            .collect();
        for k in 0..count {
            let message =
                Message { topic: Topic::FrameLatency, log_time_ns: k, publish_time_ns: 0, data: &data };
            file.write(&message).unwrap();
        }
    }

    #[test]
    fn a_finished_file_has_its_summary_and_zstd_chunks() {
        let path = std::env::temp_dir().join(format!("primm-record-finished-{}.mcap", std::process::id()));
        let mut file = McapFile::create(&path).unwrap();
        write_messages(&mut file, 3000);
        file.finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
        assert_eq!(summary.stats.unwrap().message_count, 3000);
        assert!(
            summary.chunk_indexes.len() >= 2 && summary.chunk_indexes.iter().all(|c| c.compression == "zstd")
        );
        let _ = std::fs::remove_file(&path);
    }

    #[test]
    fn a_file_cut_short_keeps_its_complete_chunks_readable() {
        let path = std::env::temp_dir().join(format!("primm-record-cut-{}.mcap", std::process::id()));
        let mut file = McapFile::create(&path).unwrap();
        write_messages(&mut file, 3000);
        // As if the process were killed: nothing more is written, not even the buffered bytes.
        std::mem::forget(file);
        let bytes = std::fs::read(&path).unwrap();
        assert!(mcap::Summary::read(&bytes).is_err() || mcap::Summary::read(&bytes).unwrap().is_none());
        let readable = mcap::MessageStream::new(&bytes).unwrap().take_while(Result::is_ok).count();
        assert!(readable >= 1000, "{readable} messages readable");
        let _ = std::fs::remove_file(&path);
    }
}
