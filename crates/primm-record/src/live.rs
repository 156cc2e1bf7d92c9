//! The live view: a Foxglove WebSocket server ([`LiveServer`]) streaming the messages of a
//! recording while the tracker runs, fed by [`LiveView`] from a subscriber on a thread of its
//! own.
//!
//! The server runs on the Foxglove SDK's own threads; [`LiveView`]'s thread subscribes to the
//! three streams like any other subscriber, encodes and logs. Nothing of it runs on the tracking
//! thread, and a slow or dead viewer only loses its own frames (safe overflow). The server
//! binds to the address it is given; primm's programs default to loopback (`127.0.0.1:8765`).

use crate::encoder::FrameEncoder;
use crate::recorder::{record, RecordLimits, StreamPorts};
use crate::topics::{Message, MessageSink, SinkError, Topic};
use crate::transforms::RadarPose;
use foxglove::{Context, PartialMetadata, RawChannel, WebSocketServer, WebSocketServerHandle};
use primm_ipc::ServiceNames;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;

/// The address the live view listens on unless told otherwise: loopback, Foxglove's port.
pub const DEFAULT_ADDRESS: &str = "127.0.0.1:8765";

/// Why the live view could not start.
#[derive(Debug, thiserror::Error)]
pub enum LiveServerError {
    /// The server could not listen on the address (in use, not local, not permitted).
    #[error("cannot serve the Foxglove view on {address}: {source}")]
    Bind {
        /// The address asked for.
        address: SocketAddr,
        /// The SDK's error.
        source: foxglove::FoxgloveError,
    },
    /// A channel could not be created.
    #[error("cannot create the Foxglove channel {topic}: {source}")]
    Channel {
        /// The topic.
        topic: &'static str,
        /// The SDK's error.
        source: foxglove::FoxgloveError,
    },
    /// The view's thread could not be started.
    #[error("cannot start the live view's thread: {0}")]
    Thread(std::io::Error),
    /// The view's thread could not subscribe to the streams.
    #[error("the live view cannot subscribe: {0}")]
    Subscribe(String),
}

/// A Foxglove WebSocket server with a channel per topic.
pub struct LiveServer {
    handle: Option<WebSocketServerHandle>,
    address: SocketAddr,
    channels: Vec<Arc<RawChannel>>,
    _context: Arc<Context>,
}

impl std::fmt::Debug for LiveServer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LiveServer").field("address", &self.address).finish()
    }
}

impl LiveServer {
    /// Starts the server on `address` (port 0: any free port) and advertises every topic.
    pub fn start(address: SocketAddr) -> Result<Self, LiveServerError> {
        let context = Context::new();
        let mut channels = Vec::with_capacity(Topic::COUNT);
        for topic in Topic::ALL {
            let channel = context
                .channel_builder(topic.name())
                .message_encoding(topic.message_encoding())
                .schema(topic.schema())
                .metadata(topic.metadata())
                .build_raw()
                .map_err(|source| LiveServerError::Channel { topic: topic.name(), source })?;
            channels.push(channel);
        }
        let handle = WebSocketServer::new()
            .name("primm")
            .bind(address.ip().to_string(), address.port())
            .context(&context)
            .start_blocking()
            .map_err(|source| LiveServerError::Bind { address, source })?;
        let address = SocketAddr::new(address.ip(), handle.port());
        Ok(Self { handle: Some(handle), address, channels, _context: context })
    }

    /// The address it listens on (with the port chosen when asked for port 0).
    pub fn local_address(&self) -> SocketAddr {
        self.address
    }

    /// Clients connected now.
    pub fn client_count(&self) -> usize {
        self.handle.as_ref().map_or(0, WebSocketServerHandle::client_count)
    }

    /// Stops the server and waits until it has.
    pub fn stop(mut self) {
        if let Some(handle) = self.handle.take() {
            handle.stop().wait_blocking();
        }
    }
}

impl MessageSink for LiveServer {
    fn write(&mut self, message: &Message<'_>) -> Result<(), SinkError> {
        let metadata = PartialMetadata { log_time: Some(message.log_time_ns) };
        self.channels[message.topic.index()].log_with_meta(message.data, metadata);
        Ok(())
    }
}

/// The live view's thread: subscribes to the streams of `names` and streams them through a
/// [`LiveServer`] until dropped.
#[derive(Debug)]
pub struct LiveView {
    address: SocketAddr,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl LiveView {
    /// Starts the server on `address` on the calling thread (so that an address in use is an
    /// error here), then the view's thread, which subscribes before this returns.
    pub fn start(
        address: SocketAddr,
        names: &ServiceNames,
        radars: Vec<RadarPose>,
    ) -> Result<Self, LiveServerError> {
        let server = LiveServer::start(address)?;
        let address = server.local_address();
        let stop = Arc::new(AtomicBool::new(false));
        let (ready_tx, ready_rx) = std::sync::mpsc::sync_channel(1);
        let thread = {
            let stop = Arc::clone(&stop);
            let names = names.clone();
            std::thread::Builder::new()
                .name("foxglove-view".to_owned())
                .spawn(move || view_thread(server, &names, radars, &stop, ready_tx))
                .map_err(LiveServerError::Thread)?
        };
        let view = Self { address, stop, thread: Some(thread) };
        match ready_rx.recv() {
            Ok(Ok(())) => Ok(view),
            Ok(Err(reason)) => Err(LiveServerError::Subscribe(reason)),
            Err(_) => Err(LiveServerError::Subscribe("the thread ended before subscribing".to_owned())),
        }
    }

    /// The address the server listens on.
    pub fn local_address(&self) -> SocketAddr {
        self.address
    }
}

impl Drop for LiveView {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The nice value of the live view's thread: on a host without a core to spare, the scheduler
/// gives the tracking thread (nice 0 or real-time) the CPU first, and the view loses its own
/// frames instead (safe overflow).
const VIEW_NICE: libc::c_int = 10;

/// Lowers the calling thread's scheduling priority to [`VIEW_NICE`] (Linux sets nice values per
/// thread); a refusal is logged and the view runs at the priority it has.
fn yield_to_tracking() {
    // SAFETY: plain system calls on the calling thread, no pointers.
    let result = unsafe {
        let thread = libc::gettid() as libc::id_t;
        libc::setpriority(libc::PRIO_PROCESS, thread, VIEW_NICE)
    };
    if result != 0 {
        tracing::warn!(error = %std::io::Error::last_os_error(), "the live view keeps its priority");
    }
}

/// The body of the live view's thread.
fn view_thread(
    mut server: LiveServer,
    names: &ServiceNames,
    radars: Vec<RadarPose>,
    stop: &AtomicBool,
    ready: std::sync::mpsc::SyncSender<Result<(), String>>,
) {
    yield_to_tracking();
    let ports = match StreamPorts::open(names, None, "primm-foxglove-view") {
        Ok(ports) => ports,
        Err(error) => {
            let _ = ready.send(Err(error.to_string()));
            server.stop();
            return;
        }
    };
    let _ = ready.send(Ok(()));
    tracing::info!(address = %server.local_address(), "Foxglove live view serving (open ws://{} in Foxglove)", server.local_address());
    let mut encoder = FrameEncoder::new(radars);
    let result =
        record(&ports, &mut encoder, &mut server, &RecordLimits::default(), &|| stop.load(Ordering::Relaxed));
    if let Err(error) = result {
        tracing::warn!(%error, "the Foxglove live view stopped; tracking goes on");
    }
    drop(ports);
    server.stop();
}

/// Parses `--foxglove`'s address (`HOST:PORT`, an IP address).
pub fn parse_address(text: &str) -> Result<SocketAddr, String> {
    text.parse().map_err(|_| format!("`{text}` is not an address such as {DEFAULT_ADDRESS}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_address_is_loopback() {
        assert!(parse_address(DEFAULT_ADDRESS).unwrap().ip().is_loopback());
        assert!(parse_address("localhost").is_err());
    }

    #[test]
    fn the_server_listens_on_loopback_and_an_address_in_use_is_an_error() {
        let server = LiveServer::start(parse_address("127.0.0.1:0").unwrap()).unwrap();
        let address = server.local_address();
        assert!(address.ip().is_loopback() && address.port() != 0);
        assert!(std::net::TcpStream::connect(address).is_ok());
        let error = LiveServer::start(address).unwrap_err();
        assert!(error.to_string().contains(&address.to_string()), "{error}");
        server.stop();
    }
}

/// `--foxglove [ADDRESS]`, shared by the programs that offer the live view.
#[derive(Debug, Clone, Default, PartialEq, Eq, clap::Args)]
pub struct FoxgloveArgs {
    /// Serve a live Foxglove view (WebSocket) on this address while running: open
    /// `ws://ADDRESS` in Foxglove. Without a value: 127.0.0.1:8765 (loopback; give another
    /// address, e.g. 0.0.0.0:8765, to let other hosts connect).
    #[arg(long, value_name = "ADDRESS", num_args = 0..=1, default_missing_value = DEFAULT_ADDRESS, value_parser = parse_address)]
    pub foxglove: Option<SocketAddr>,
}

#[cfg(test)]
mod argument_tests {
    use super::*;
    use clap::Parser;

    #[derive(Debug, Parser)]
    struct Command {
        #[command(flatten)]
        view: FoxgloveArgs,
    }

    #[test]
    fn foxglove_without_an_address_serves_on_loopback() {
        let parsed = Command::try_parse_from(["primm", "--foxglove"]).unwrap();
        let address = parsed.view.foxglove.unwrap();
        assert!(address.ip().is_loopback(), "{address}");
        assert_eq!(address.port(), 8765);
        assert_eq!(Command::try_parse_from(["primm"]).unwrap().view.foxglove, None);
        let chosen = Command::try_parse_from(["primm", "--foxglove", "0.0.0.0:9000"]).unwrap();
        assert_eq!(chosen.view.foxglove.unwrap().port(), 9000);
    }
}
