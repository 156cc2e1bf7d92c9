//! # primm-record: primm's streams in MCAP files and in a live Foxglove view
//!
//! Everything the tracker service sends over shared memory (`primm/measurements`,
//! `primm/tracks`, `primm/latency`) turned into messages that the Foxglove app, the `mcap` tools
//! and any MCAP reader understand:
//!
//! - the wire payloads themselves, byte for byte (a schema of their own that names the wire
//!   version), so that nothing is lost and a recording can be replayed into the service
//!   ([`raw`], [`reading`]);
//! - Foxglove's well-known messages for viewing: a `SceneUpdate` of the tracks (a box per track
//!   with its id and class, a velocity arrow and the 2σ position ellipse), one of the detections
//!   (coloured by class; detections taken by a track and clutter marked), one of the ground truth
//!   where the frames carry it, `FrameTransforms` world → vehicle → each radar, and the
//!   tracker's latencies as JSON that the Plot panel reads ([`scene`], [`detections`],
//!   [`transforms`], [`latency`]).
//!
//! [`FrameEncoder`] turns wire frames into these [`Message`]s and hands them to a
//! [`MessageSink`]: an MCAP file ([`McapFile`], chunked and zstd-compressed) or a Foxglove
//! WebSocket server ([`LiveServer`]). [`recorder`] reads the three streams from shared memory on
//! the calling thread and feeds a sink; [`live::LiveView`] does the same on a thread of its own
//! for `--foxglove`, so that the tracking thread never encodes a message. Every message's log
//! time is the frame's sensor time; its publish time is the sender's `CLOCK_MONOTONIC` time.
//! Topics, schemas and units: `docs/recording.md`.

pub mod client;
pub mod detections;
pub mod encoder;
pub mod latency;
pub mod live;
pub mod mcap_file;
pub mod raw;
pub mod reading;
pub mod recorder;
pub mod scene;
pub mod topics;
pub mod transforms;

pub use encoder::FrameEncoder;
pub use live::{LiveServer, LiveServerError, LiveView};
pub use mcap_file::{McapFile, McapFileError};
pub use topics::{Message, MessageSink, SinkError, Topic};
