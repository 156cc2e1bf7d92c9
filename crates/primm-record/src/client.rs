//! A small client of the Foxglove WebSocket protocol (`foxglove.sdk.v1`): it connects,
//! takes the channel advertisement, subscribes to every channel and reads the messages. It is
//! what the tests and `primm bench-service --foxglove-client` connect to the live view with; the
//! message types are the Foxglove SDK's own.

use foxglove::ws_protocol::client::{Subscribe, Subscription};
use foxglove::ws_protocol::server::ServerMessage;
use foxglove::ws_protocol::JsonMessage;
use std::collections::HashMap;
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};
use tungstenite::client::IntoClientRequest;
use tungstenite::http::HeaderValue;
use tungstenite::WebSocket;

/// The subprotocol the Foxglove SDK's server speaks: the Foxglove WebSocket protocol v1, named
/// `foxglove.sdk.v1` (the SDK refuses the older name `foxglove.websocket.v1`).
pub const SUBPROTOCOL: &str = "foxglove.sdk.v1";

/// How long one read waits before [`LiveClient::next_message`] returns `None`.
const READ_TIMEOUT: Duration = Duration::from_millis(200);

/// Why the client failed.
#[derive(Debug, thiserror::Error)]
pub enum LiveClientError {
    /// No TCP connection.
    #[error("cannot connect to {address}: {source}")]
    Connect {
        /// The server's address.
        address: SocketAddr,
        /// The OS error.
        source: std::io::Error,
    },
    /// The WebSocket handshake or a read or write failed.
    #[error("WebSocket: {0}")]
    WebSocket(String),
    /// A server message could not be parsed.
    #[error("cannot parse a server message: {0}")]
    Parse(String),
    /// No channel was advertised in time.
    #[error("no channel advertised within {0:?}")]
    NoChannels(Duration),
}

/// One received message.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReceivedMessage {
    /// Its topic.
    pub topic: String,
    /// Its log time, ns.
    pub log_time_ns: u64,
    /// Its bytes.
    pub data: Vec<u8>,
}

/// A channel the server advertised.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AdvertisedChannel {
    /// The server's channel id.
    pub id: u64,
    /// Its topic.
    pub topic: String,
    /// Its message encoding.
    pub encoding: String,
    /// Its schema's name.
    pub schema_name: String,
}

/// A connected client.
#[derive(Debug)]
pub struct LiveClient {
    socket: WebSocket<TcpStream>,
    channels: Vec<AdvertisedChannel>,
    subscriptions: HashMap<u32, String>,
}

fn websocket_error(error: impl std::fmt::Display) -> LiveClientError {
    LiveClientError::WebSocket(error.to_string())
}

impl LiveClient {
    /// Connects to `ws://address` with the Foxglove subprotocol.
    pub fn connect(address: SocketAddr, timeout: Duration) -> Result<Self, LiveClientError> {
        let stream = TcpStream::connect_timeout(&address, timeout)
            .map_err(|source| LiveClientError::Connect { address, source })?;
        stream
            .set_read_timeout(Some(timeout))
            .map_err(|source| LiveClientError::Connect { address, source })?;
        let mut request = format!("ws://{address}/").into_client_request().map_err(websocket_error)?;
        request.headers_mut().insert("Sec-WebSocket-Protocol", HeaderValue::from_static(SUBPROTOCOL));
        let (socket, _) = tungstenite::client::client(request, stream).map_err(websocket_error)?;
        socket
            .get_ref()
            .set_read_timeout(Some(READ_TIMEOUT))
            .map_err(|source| LiveClientError::Connect { address, source })?;
        Ok(Self { socket, channels: Vec::new(), subscriptions: HashMap::new() })
    }

    /// The channels advertised so far.
    pub fn channels(&self) -> &[AdvertisedChannel] {
        &self.channels
    }

    /// Waits up to `timeout` for `expected` channels to be advertised (at least one), then
    /// subscribes to every advertised channel; returns how many.
    pub fn subscribe_all(&mut self, expected: usize, timeout: Duration) -> Result<usize, LiveClientError> {
        let deadline = Instant::now() + timeout;
        while self.channels.len() < expected.max(1) && Instant::now() < deadline {
            self.read_one()?;
        }
        if self.channels.is_empty() {
            return Err(LiveClientError::NoChannels(timeout));
        }
        let subscriptions: Vec<Subscription> = self
            .channels
            .iter()
            .enumerate()
            .map(|(index, channel)| Subscription::new(index as u32, channel.id))
            .collect();
        for subscription in &subscriptions {
            self.subscriptions.insert(subscription.id, self.channels[subscription.id as usize].topic.clone());
        }
        let text = Subscribe::new(subscriptions).to_string();
        self.socket.send(tungstenite::Message::text(text)).map_err(websocket_error)?;
        Ok(self.channels.len())
    }

    /// Reads one WebSocket message: records advertisements, returns message data; `None` after
    /// a read time-out or for any other message.
    fn read_one(&mut self) -> Result<Option<ReceivedMessage>, LiveClientError> {
        let message = match self.socket.read() {
            Ok(message) => message,
            Err(tungstenite::Error::Io(error))
                if matches!(error.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut) =>
            {
                return Ok(None)
            }
            Err(error) => return Err(websocket_error(error)),
        };
        match message {
            tungstenite::Message::Text(text) => {
                if let ServerMessage::Advertise(advertise) =
                    ServerMessage::parse_json(&text).map_err(|e| LiveClientError::Parse(e.to_string()))?
                {
                    self.channels.extend(advertise.channels.iter().map(|channel| AdvertisedChannel {
                        id: channel.id,
                        topic: channel.topic.to_string(),
                        encoding: channel.encoding.to_string(),
                        schema_name: channel.schema_name.to_string(),
                    }));
                }
                Ok(None)
            }
            tungstenite::Message::Binary(data) => {
                match ServerMessage::parse_binary(&data).map_err(|e| LiveClientError::Parse(e.to_string()))? {
                    ServerMessage::MessageData(message) => Ok(Some(ReceivedMessage {
                        topic: self.subscriptions.get(&message.subscription_id).cloned().unwrap_or_default(),
                        log_time_ns: message.log_time,
                        data: message.data.into_owned(),
                    })),
                    _ => Ok(None),
                }
            }
            _ => Ok(None),
        }
    }

    /// Closes the connection with the WebSocket closing handshake (bounded by the read
    /// time-out), so that the server sees a client leave rather than a reset connection.
    pub fn close(mut self) {
        if self.socket.close(None).is_ok() {
            // Read until the server's close frame (or an error, or the time-out) ends the
            // handshake.
            while self.socket.read().is_ok() {}
        }
    }

    /// The next message of a subscribed channel, or `None` when none came within a read
    /// time-out (200 ms).
    pub fn next_message(&mut self) -> Result<Option<ReceivedMessage>, LiveClientError> {
        self.read_one()
    }
}
