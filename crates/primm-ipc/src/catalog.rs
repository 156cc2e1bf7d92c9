//! The services of the tracker, their names and their quality of service, in one place.
//!
//! Every primm program opens a service through this module with the same settings, so
//! whichever program starts first creates it exactly as the others expect. Each pub/sub service
//! has an event service of the same name (iceoryx2 tells services apart by name *and*
//! messaging pattern); a sender notifies it after every sample so that receivers can sleep.
//!
//! | service | payload | subscriber buffer | history | publishers | subscribers |
//! |---|---|---|---|---|---|
//! | `primm/measurements` | [`MeasurementFrame`] | 64 | 0 | 4 | 8 |
//! | `primm/tracks` | [`TrackFrame`] | 16 | 0 | 2 | 8 |
//! | `primm/latency` | [`LatencyReport`] | 4 | 1 | 2 | 8 |
//!
//! Safe overflow is on everywhere: a full subscriber buffer drops its *oldest* sample, so a slow
//! or stopped subscriber can never block a sender, in particular never the tracker. The
//! tracker's input buffer holds 64 frames (1 to 4 s of radar), deep enough to absorb bursts and
//! scheduling hiccups; frames lost anyway show up as gaps in the sequence numbers, which the
//! tracker counts. No history on the data streams: a late tracker or viewer starts with the
//! next frame instead of stale ones. The latency service keeps one report of history so that a
//! late viewer sees the current figures at once. Two publishers per stream let a restarted
//! publisher connect while the dead one's port is still being cleaned up.

use core::fmt::Debug;
use iceoryx2::node::NodeCreationFailure;
use iceoryx2::port::listener::{Listener, ListenerCreateError};
use iceoryx2::port::notifier::{Notifier, NotifierCreateError};
use iceoryx2::port::publisher::{Publisher, PublisherCreateError};
use iceoryx2::port::subscriber::{Subscriber, SubscriberCreateError};
use iceoryx2::prelude::*;
use iceoryx2::service::builder::event::EventOpenOrCreateError;
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenOrCreateError;
use iceoryx2::service::port_factory::{event, publish_subscribe};
use primm_wire::{LatencyReport, MeasurementFrame, TrackFrame};

/// The iceoryx2 service variant primm uses: inter-process, shared memory.
pub type Ipc = ipc::Service;

/// Base name of the measurement stream.
pub const MEASUREMENTS: &str = "primm/measurements";
/// Base name of the track stream.
pub const TRACKS: &str = "primm/tracks";
/// Base name of the latency reports.
pub const LATENCY: &str = "primm/latency";

/// Environment variable read by every primm program as the default service-name prefix.
pub const SERVICE_PREFIX_ENV: &str = "PRIMM_SERVICE_PREFIX";

/// Quality of service of one pub/sub stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StreamQos {
    /// Largest buffer a subscriber may ask for, and the buffer primm's subscribers use.
    pub subscriber_buffer: usize,
    /// Samples kept for late subscribers.
    pub history: usize,
    /// Publishers at once.
    pub max_publishers: usize,
    /// Subscribers at once.
    pub max_subscribers: usize,
    /// Samples a subscriber may hold at once.
    pub max_borrowed: usize,
}

/// QoS of `primm/measurements`.
pub const MEASUREMENTS_QOS: StreamQos =
    StreamQos { subscriber_buffer: 64, history: 0, max_publishers: 4, max_subscribers: 8, max_borrowed: 2 };
/// QoS of `primm/tracks`.
pub const TRACKS_QOS: StreamQos =
    StreamQos { subscriber_buffer: 16, history: 0, max_publishers: 2, max_subscribers: 8, max_borrowed: 2 };
/// QoS of `primm/latency`.
pub const LATENCY_QOS: StreamQos =
    StreamQos { subscriber_buffer: 4, history: 1, max_publishers: 2, max_subscribers: 8, max_borrowed: 2 };

/// Why a primm service or port could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum ConnectError {
    /// The prefix makes an invalid iceoryx2 service name.
    #[error("invalid service name '{name}': {reason:?}")]
    InvalidName {
        /// The full name.
        name: String,
        /// iceoryx2's reason.
        reason: iceoryx2::service::service_name::ServiceNameError,
    },
    /// The iceoryx2 domain in [`ICEORYX2_DOMAIN_ENV`] is not a valid file-name prefix.
    #[error("invalid iceoryx2 domain '{domain}' in {ICEORYX2_DOMAIN_ENV}: {reason:?}")]
    InvalidDomain {
        /// The domain as given.
        domain: String,
        /// Why iceoryx2 refuses it as a file name.
        reason: SemanticStringError,
    },
    /// The iceoryx2 node could not be created.
    #[error("cannot create the iceoryx2 node: {0}")]
    Node(NodeCreationFailure),
    /// The pub/sub service could not be opened or created (e.g. it exists with another payload
    /// layout or incompatible QoS).
    #[error("cannot open the pub/sub service '{service}': {source}")]
    PublishSubscribe {
        /// Service name.
        service: String,
        /// iceoryx2's error.
        source: PublishSubscribeOpenOrCreateError,
    },
    /// The event service could not be opened or created.
    #[error("cannot open the event service '{service}': {source}")]
    Event {
        /// Service name.
        service: String,
        /// iceoryx2's error.
        source: EventOpenOrCreateError,
    },
    /// No publisher port (e.g. too many publishers).
    #[error("cannot create a publisher on '{service}': {source}")]
    Publisher {
        /// Service name.
        service: String,
        /// iceoryx2's error.
        source: PublisherCreateError,
    },
    /// No subscriber port (e.g. too many subscribers).
    #[error("cannot create a subscriber on '{service}': {source}")]
    Subscriber {
        /// Service name.
        service: String,
        /// iceoryx2's error.
        source: SubscriberCreateError,
    },
    /// No notifier port.
    #[error("cannot create a notifier on '{service}': {source}")]
    Notifier {
        /// Service name.
        service: String,
        /// iceoryx2's error.
        source: NotifierCreateError,
    },
    /// No listener port.
    #[error("cannot create a listener on '{service}': {source}")]
    Listener {
        /// Service name.
        service: String,
        /// iceoryx2's error.
        source: ListenerCreateError,
    },
}

/// The full service names, with an optional prefix so that several independent setups (e.g.
/// parallel tests) share one machine.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ServiceNames {
    prefix: String,
}

impl ServiceNames {
    /// Names under `prefix` (`""` for the standard names, else `PREFIX/primm/...`).
    pub fn new(prefix: &str) -> Self {
        Self { prefix: prefix.trim_matches('/').to_owned() }
    }

    /// The prefix.
    pub fn prefix(&self) -> &str {
        &self.prefix
    }

    fn full(&self, base: &str) -> String {
        if self.prefix.is_empty() {
            base.to_owned()
        } else {
            format!("{}/{base}", self.prefix)
        }
    }

    /// Full name of the measurement stream.
    pub fn measurements(&self) -> String {
        self.full(MEASUREMENTS)
    }

    /// Full name of the track stream.
    pub fn tracks(&self) -> String {
        self.full(TRACKS)
    }

    /// Full name of the latency reports.
    pub fn latency(&self) -> String {
        self.full(LATENCY)
    }
}

/// Environment variable naming the iceoryx2 domain primm's programs use: the prefix of every
/// file iceoryx2 creates in `/dev/shm` and in its directory under `/tmp` (default `iox2_`, the
/// domain every iceoryx2 program shares). Programs in different domains never see each other,
/// so a private domain isolates a setup completely (the integration tests use one each).
pub const ICEORYX2_DOMAIN_ENV: &str = "PRIMM_ICEORYX2_DOMAIN";

/// The iceoryx2 configuration of primm's nodes: iceoryx2's global configuration, in the domain
/// [`ICEORYX2_DOMAIN_ENV`] names (if set), with the removal of dead nodes left to
/// [`create_node`] so that it can count them.
pub fn iceoryx2_config() -> Result<Config, ConnectError> {
    iceoryx2_config_in(std::env::var(ICEORYX2_DOMAIN_ENV).ok().as_deref())
}

/// [`iceoryx2_config`] in the domain `domain` (iceoryx2's default domain when `None`), whatever
/// [`ICEORYX2_DOMAIN_ENV`] says: for a program that works in two domains at once, such as a
/// test of the host-to-host tunnel.
pub fn iceoryx2_config_in(domain: Option<&str>) -> Result<Config, ConnectError> {
    quiet_iceoryx2();
    let mut config = Config::global_config().clone();
    if let Some(domain) = domain {
        config.global.prefix = FileName::new(domain.as_bytes())
            .map_err(|reason| ConnectError::InvalidDomain { domain: domain.to_owned(), reason })?;
    }
    config.global.node.cleanup_dead_nodes_on_creation = false;
    Ok(config)
}

/// iceoryx2 logs to the console on its own; keep it to errors unless IOX2_LOG_LEVEL says
/// otherwise (primm's own logs go through `tracing`). Done once, before iceoryx2 is first used,
/// so that a program may raise the level afterwards.
fn quiet_iceoryx2() {
    static QUIET_ICEORYX2: std::sync::Once = std::sync::Once::new();
    QUIET_ICEORYX2.call_once(|| set_log_level_from_env_or(LogLevel::Error));
}

/// Creates a node named `name` that leaves SIGINT/SIGTERM to the program (see
/// [`crate::shutdown`]), in the domain of [`iceoryx2_config`].
///
/// It then removes, through iceoryx2's own bookkeeping (`Node::try_cleanup_dead_nodes`), the
/// resources of every node of the domain whose process died without cleaning up (e.g. after
/// `kill -9`): their shared-memory segments, their ports in the services they used, and services
/// only they still held. How many were removed is logged (and how many could not be, e.g. while
/// another process is removing them), so a restarted program starts clean and says so.
///
/// Dropping the node (after every port and service handle made from it) removes all of its own
/// resources; a program that returns from `main` normally leaves nothing of its own in
/// `/dev/shm`. One file stays by design: the domain's node counter
/// (`<domain><hash>_node.<version>.global_mgmt`, 16 bytes), which iceoryx2 creates once per domain
/// and version without an owner, shares with every process of the domain and never removes.
pub fn create_node(name: &str) -> Result<Node<Ipc>, ConnectError> {
    create_node_with(name, &iceoryx2_config()?)
}

/// [`create_node`] with the configuration `config` (e.g. from [`iceoryx2_config_in`]).
pub fn create_node_with(name: &str, config: &Config) -> Result<Node<Ipc>, ConnectError> {
    quiet_iceoryx2();
    let mut builder = NodeBuilder::new().config(config).signal_handling_mode(SignalHandlingMode::Disabled);
    if let Ok(node_name) = NodeName::new(name) {
        builder = builder.name(&node_name);
    }
    let node = builder.create::<Ipc>().map_err(ConnectError::Node)?;
    let cleanup = node.try_cleanup_dead_nodes();
    if cleanup.cleanups > 0 {
        tracing::info!(
            removed = cleanup.cleanups,
            domain = %config.global.prefix,
            "removed the resources of {} dead iceoryx2 node(s)",
            cleanup.cleanups
        );
    }
    if cleanup.failed_cleanups > 0 {
        tracing::warn!(
            failed = cleanup.failed_cleanups,
            domain = %config.global.prefix,
            "could not remove the resources of {} dead iceoryx2 node(s)",
            cleanup.failed_cleanups
        );
    }
    Ok(node)
}

/// One opened stream: the pub/sub service and its event service.
#[derive(Debug)]
pub struct Stream<T: Debug + ZeroCopySend + 'static> {
    name: String,
    qos: StreamQos,
    data: publish_subscribe::PortFactory<Ipc, T, ()>,
    events: event::PortFactory<Ipc>,
}

impl<T: Debug + ZeroCopySend + 'static> Stream<T> {
    fn open(node: &Node<Ipc>, name: String, qos: StreamQos) -> Result<Self, ConnectError> {
        let service_name = ServiceName::new(&name)
            .map_err(|reason| ConnectError::InvalidName { name: name.clone(), reason })?;
        let data = node
            .service_builder(&service_name)
            .publish_subscribe::<T>()
            .enable_safe_overflow(true)
            .subscriber_max_buffer_size(qos.subscriber_buffer)
            .history_size(qos.history)
            .max_publishers(qos.max_publishers)
            .max_subscribers(qos.max_subscribers)
            .subscriber_max_borrowed_samples(qos.max_borrowed)
            .open_or_create()
            .map_err(|source| ConnectError::PublishSubscribe { service: name.clone(), source })?;
        let events = node
            .service_builder(&service_name)
            .event()
            .open_or_create()
            .map_err(|source| ConnectError::Event { service: name.clone(), source })?;
        Ok(Self { name, qos, data, events })
    }

    /// The service name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// A publisher port.
    pub fn publisher(&self) -> Result<Publisher<Ipc, T, ()>, ConnectError> {
        self.data
            .publisher_builder()
            .create()
            .map_err(|source| ConnectError::Publisher { service: self.name.clone(), source })
    }

    /// A subscriber port with the stream's buffer size.
    pub fn subscriber(&self) -> Result<Subscriber<Ipc, T, ()>, ConnectError> {
        self.data
            .subscriber_builder()
            .buffer_size(self.qos.subscriber_buffer)
            .create()
            .map_err(|source| ConnectError::Subscriber { service: self.name.clone(), source })
    }

    /// A notifier port on the stream's event service.
    pub fn notifier(&self) -> Result<Notifier<Ipc>, ConnectError> {
        self.events
            .notifier_builder()
            .create()
            .map_err(|source| ConnectError::Notifier { service: self.name.clone(), source })
    }

    /// A listener port on the stream's event service.
    pub fn listener(&self) -> Result<Listener<Ipc>, ConnectError> {
        self.events
            .listener_builder()
            .create()
            .map_err(|source| ConnectError::Listener { service: self.name.clone(), source })
    }

    /// Subscribers connected right now.
    pub fn subscriber_count(&self) -> usize {
        self.data.dynamic_config().number_of_subscribers()
    }

    /// Publishers connected right now.
    pub fn publisher_count(&self) -> usize {
        self.data.dynamic_config().number_of_publishers()
    }
}

/// Opens (or creates) `primm/measurements` and its event service.
pub fn measurements(
    node: &Node<Ipc>,
    names: &ServiceNames,
) -> Result<Stream<MeasurementFrame>, ConnectError> {
    Stream::open(node, names.measurements(), MEASUREMENTS_QOS)
}

/// Opens (or creates) `primm/tracks` and its event service.
pub fn tracks(node: &Node<Ipc>, names: &ServiceNames) -> Result<Stream<TrackFrame>, ConnectError> {
    Stream::open(node, names.tracks(), TRACKS_QOS)
}

/// Opens (or creates) `primm/latency` and its event service.
pub fn latency(node: &Node<Ipc>, names: &ServiceNames) -> Result<Stream<LatencyReport>, ConnectError> {
    Stream::open(node, names.latency(), LATENCY_QOS)
}
