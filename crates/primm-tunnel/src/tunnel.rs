//! One side of a tunnel: primm's streams in the local domain, bridged to the peers over zenoh.

use crate::report::TunnelReport;
use crate::settings::{ZenohConfigError, ZenohSettings};
use crate::watch::StreamWatch;
use iceoryx2::config::Config;
use iceoryx2::node::NodeCreationFailure;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::ReceiveError;
use iceoryx2::prelude::*;
use iceoryx2::service::local_threadsafe;
use iceoryx2::waitset::{WaitSetAttachmentError, WaitSetCreateError, WaitSetRunError};
use iceoryx2_integrations_zenoh_link_carrier::{CreationError, ZenohCarrier};
use iceoryx2_link::{Link, WakeCreationError};
use iceoryx2_link_tunnel::Tunnel;
use primm_ipc::catalog::{self, ConnectError, Ipc, ServiceNames};
use primm_ipc::ShutdownFlag;
use primm_wire::{LatencyReport, MeasurementFrame, TrackFrame};
use std::time::{Duration, Instant};
use zenoh::Wait;

/// How often the tunnel compares what is offered here and on the far side (and reports its
/// status). Samples do not wait for it: they move as soon as a sender notifies.
pub const DISCOVERY_PERIOD: Duration = Duration::from_millis(100);

/// Why a tunnel could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum TunnelOpenError {
    /// primm's streams could not be opened in the local domain.
    #[error(transparent)]
    Connect(#[from] ConnectError),
    /// The zenoh settings make no valid configuration.
    #[error(transparent)]
    Settings(#[from] ZenohConfigError),
    /// zenoh could not open its session (e.g. the listen endpoint is taken).
    #[error("cannot open the zenoh session: {0}")]
    Session(String),
    /// The zenoh carrier could not subscribe to the peers' offers.
    #[error("cannot start the zenoh carrier: {0}")]
    Carrier(CreationError),
    /// The link's own iceoryx2 node could not be created.
    #[error("cannot create the link's iceoryx2 node: {0}")]
    LinkNode(NodeCreationFailure),
    /// The link's wake-up service could not be created.
    #[error("cannot create the link's wake-up service: {0}")]
    Wake(WakeCreationError),
}

/// Why a running tunnel stopped with an error. Failed discoveries and propagations are not
/// among them: they are counted, logged, and tried again in the next cycle.
#[derive(Debug, thiserror::Error)]
pub enum TunnelRunError {
    /// The wait set could not be created.
    #[error("cannot create the wait set: {0}")]
    WaitSetCreate(WaitSetCreateError),
    /// A listener could not be attached to the wait set.
    #[error("cannot attach a listener to the wait set: {0}")]
    WaitSetAttach(WaitSetAttachmentError),
    /// Waiting failed.
    #[error("cannot wait for events: {0}")]
    Wait(WaitSetRunError),
    /// A stream's counting subscriber failed.
    #[error("cannot receive from {stream}: {source}")]
    Receive {
        /// The stream.
        stream: String,
        /// iceoryx2's error.
        source: ReceiveError,
    },
}

/// A running tunnel's state, handed to [`StreamTunnel::run`]'s observer after every discovery.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TunnelStatus {
    /// zenoh sessions (peers, routers or clients) the session is connected to right now.
    pub peers: usize,
    /// The run's counters so far.
    pub report: TunnelReport,
}

/// primm's streams in one iceoryx2 domain, bridged through the iceoryx2 link tunnel over a
/// zenoh session.
///
/// Opening it opens `primm/measurements`, `primm/tracks` and `primm/latency` (under the given
/// prefix) with primm's own quality of service, as every primm program does, so that local
/// programs find them as they expect, whichever side starts first. The link then treats them
/// as local services: it relays what is published here to the peers and publishes here what
/// they relay, in both directions, with the event services of the same names. No other service
/// of the domain crosses.
pub struct StreamTunnel {
    // Dropped in this order: the link and its ports first, the zenoh session last.
    link: Link<Ipc, Tunnel<ZenohCarrier>>,
    link_listener: Listener<local_threadsafe::Service>,
    watches: Watches,
    listeners: [Listener<Ipc>; 3],
    _streams:
        (catalog::Stream<MeasurementFrame>, catalog::Stream<TrackFrame>, catalog::Stream<LatencyReport>),
    _node: Node<Ipc>,
    session: zenoh::Session,
    report: TunnelReport,
}

impl std::fmt::Debug for StreamTunnel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StreamTunnel")
            .field("zenoh_id", &self.session.zid())
            .field("report", &self.report)
            .finish()
    }
}

impl StreamTunnel {
    /// Opens primm's streams named by `names` in the domain `config` describes (see
    /// [`catalog::iceoryx2_config`]) and bridges them over a zenoh session made from `zenoh`.
    pub fn open(
        names: &ServiceNames,
        config: &Config,
        zenoh: &ZenohSettings,
    ) -> Result<Self, TunnelOpenError> {
        let node = catalog::create_node_with("primm-tunnel", config)?;
        let measurements = catalog::measurements(&node, names)?;
        let tracks = catalog::tracks(&node, names)?;
        let latency = catalog::latency(&node, names)?;
        let listeners = [measurements.listener()?, tracks.listener()?, latency.listener()?];
        let watches = (
            StreamWatch::new(measurements.name(), measurements.subscriber()?),
            StreamWatch::new(tracks.name(), tracks.subscriber()?),
            StreamWatch::new(latency.name(), latency.subscriber()?),
        );

        let session = zenoh::open(zenoh.zenoh_config()?)
            .wait()
            .map_err(|error| TunnelOpenError::Session(error.to_string()))?;
        let carrier = ZenohCarrier::open(session.clone()).map_err(TunnelOpenError::Carrier)?;
        let link_node = NodeBuilder::new()
            .config(config)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .name(&NodeName::new("primm-tunnel-link").expect("a valid node name"))
            .create::<Ipc>()
            .map_err(TunnelOpenError::LinkNode)?;
        let bridged: Vec<String> =
            [measurements.name(), tracks.name(), latency.name()].map(str::to_owned).into();
        let mut link = Link::new(link_node, Tunnel::new(carrier, config))
            .with_filter(move |name| bridged.iter().any(|stream| stream == name.as_str()));
        let link_listener = link.listener().map_err(TunnelOpenError::Wake)?;

        let (measurements_watch, tracks_watch, latency_watch) = watches;
        Ok(Self {
            link,
            link_listener,
            watches: Watches {
                measurements: measurements_watch,
                tracks: tracks_watch,
                latency: latency_watch,
            },
            listeners,
            _streams: (measurements, tracks, latency),
            _node: node,
            session,
            report: TunnelReport::default(),
        })
    }

    /// The zenoh session's id, as its peers know it.
    pub fn zenoh_id(&self) -> String {
        self.session.zid().to_string()
    }

    /// The endpoints this session listens on, as zenoh locators (`tcp/127.0.0.1:40123`): a
    /// listen endpoint with port 0 shows here with the port the operating system chose.
    pub fn listening_on(&self) -> Vec<String> {
        self.session.info().locators().wait().iter().map(ToString::to_string).collect()
    }

    /// zenoh sessions (peers, routers or clients) this one is connected to right now.
    pub fn peers(&self) -> usize {
        // `transports` lists every connected session whatever its role; the stable
        // `peers_zid` and `routers_zid` leave out the clients of a tunnel in router mode.
        self.session.info().transports().wait().count()
    }

    /// The counters so far.
    pub fn report(&self) -> TunnelReport {
        let mut report = self.report.clone();
        report.streams = self.watches.counts();
        report
    }

    /// Moves samples in both directions until `shutdown` is raised, then returns the counters.
    ///
    /// It sleeps until a local sender notifies one of the streams' event services, or the
    /// carrier wakes the link because something arrived, or [`DISCOVERY_PERIOD`] has passed;
    /// then it moves whatever is pending. Every [`DISCOVERY_PERIOD`] it also runs the link's
    /// discovery and calls `observe` with the status.
    pub fn run(
        &mut self,
        shutdown: &ShutdownFlag,
        mut observe: impl FnMut(&TunnelStatus),
    ) -> Result<TunnelReport, TunnelRunError> {
        let waitset = WaitSetBuilder::new()
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<Ipc>()
            .map_err(TunnelRunError::WaitSetCreate)?;
        let _link_guard =
            waitset.attach_notification(&self.link_listener).map_err(TunnelRunError::WaitSetAttach)?;
        let _stream_guards = self
            .listeners
            .iter()
            .map(|listener| waitset.attach_notification(listener))
            .collect::<Result<Vec<_>, _>>()
            .map_err(TunnelRunError::WaitSetAttach)?;

        let mut next_discovery = Instant::now();
        loop {
            let stopping = shutdown.is_requested();
            // Take the notifications first, so that one arriving while samples move wakes the
            // next wait instead of being lost.
            let _ = self.link_listener.try_wait(|_| {});
            for listener in &self.listeners {
                let _ = listener.try_wait(|_| {});
            }
            let discover = stopping || Instant::now() >= next_discovery;
            if discover {
                if let Err(error) = self.link.discover() {
                    self.report.discovery_failures += 1;
                    tracing::warn!(%error, "tunnel discovery failed; trying again in the next cycle");
                }
                self.report.discoveries += 1;
                next_discovery = Instant::now() + DISCOVERY_PERIOD;
            }
            if let Err(error) = self.link.propagate() {
                self.report.propagation_failures += 1;
                tracing::warn!(%error, "tunnel propagation failed; trying again in the next cycle");
            }
            self.report.cycles += 1;
            self.watches.drain(self.link.node().id())?;
            if discover {
                let peers = self.peers();
                self.report.peers_max = self.report.peers_max.max(peers);
                observe(&TunnelStatus { peers, report: self.report() });
            }
            if stopping {
                break;
            }
            let timeout = next_discovery.saturating_duration_since(Instant::now());
            waitset
                .wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, timeout)
                .map_err(TunnelRunError::Wait)?;
        }
        Ok(self.report())
    }
}

/// The counters of the three streams.
struct Watches {
    measurements: StreamWatch<MeasurementFrame>,
    tracks: StreamWatch<TrackFrame>,
    latency: StreamWatch<LatencyReport>,
}

impl Watches {
    /// Counts every pending sample of each stream; `link_node` publishes what arrives.
    fn drain(&mut self, link_node: &iceoryx2::identifiers::UniqueNodeId) -> Result<(), TunnelRunError> {
        fn failed(stream: &str) -> impl FnOnce(ReceiveError) -> TunnelRunError + '_ {
            move |source| TunnelRunError::Receive { stream: stream.to_owned(), source }
        }
        self.measurements.drain(link_node).map_err(failed(self.measurements.name()))?;
        self.tracks.drain(link_node).map_err(failed(self.tracks.name()))?;
        self.latency.drain(link_node).map_err(failed(self.latency.name()))?;
        Ok(())
    }

    /// Per stream, by service name.
    fn counts(&self) -> Vec<(String, crate::watch::StreamCounts)> {
        vec![
            (self.measurements.name().to_owned(), self.measurements.counts()),
            (self.tracks.name().to_owned(), self.tracks.counts()),
            (self.latency.name().to_owned(), self.latency.counts()),
        ]
    }
}
