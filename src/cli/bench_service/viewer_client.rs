//! `bench-service --foxglove-client`: a Foxglove WebSocket client connected to the tracker's
//! live view for the whole trial, subscribed to every topic, so that the benchmark measures
//! the tracker while a viewer watches.

use primm_record::client::LiveClient;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How long the client keeps trying to connect while the tracker's view starts.
const CONNECT_TIMEOUT: Duration = Duration::from_secs(10);

/// A client reading the live view on a thread of its own.
pub struct ViewerClient {
    stop: Arc<AtomicBool>,
    thread: JoinHandle<Result<u64, String>>,
}

impl ViewerClient {
    /// Connects to `address` (retrying until the view listens) and subscribes to every topic;
    /// fails if it cannot within [`CONNECT_TIMEOUT`].
    pub fn start(address: SocketAddr) -> Result<Self, String> {
        let deadline = Instant::now() + CONNECT_TIMEOUT;
        let mut client = loop {
            match LiveClient::connect(address, Duration::from_secs(2)) {
                Ok(client) => break client,
                Err(error) if Instant::now() >= deadline => return Err(error.to_string()),
                Err(_) => std::thread::sleep(Duration::from_millis(100)),
            }
        };
        let channels = client
            .subscribe_all(primm_record::Topic::COUNT, Duration::from_secs(5))
            .map_err(|e| e.to_string())?;
        println!("Foxglove client on ws://{address}: subscribed to {channels} channels");
        let stop = Arc::new(AtomicBool::new(false));
        let thread = {
            let stop = Arc::clone(&stop);
            std::thread::spawn(move || {
                let mut received = 0;
                while !stop.load(Ordering::Relaxed) {
                    if client.next_message().map_err(|e| e.to_string())?.is_some() {
                        received += 1;
                    }
                }
                client.close();
                Ok(received)
            })
        };
        Ok(Self { stop, thread })
    }

    /// Stops reading; the messages received, or why reading failed.
    pub fn finish(self) -> Result<u64, String> {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.join().map_err(|_| "the client's thread panicked".to_owned())?
    }
}
