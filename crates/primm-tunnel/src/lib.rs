//! primm's streams across hosts, through iceoryx2's own host-to-host link.
//!
//! iceoryx2 ends at the boundary of shared memory. In a vehicle the radars, the tracker and the
//! consumers of tracks often sit on different ECUs, so this crate extends primm's three streams
//! (`primm/measurements`, `primm/tracks`, `primm/latency`, each with its event service) to other
//! hosts with the link that iceoryx2 0.10 ships: a [`Link`](iceoryx2_link::Link) core, its
//! [`Tunnel`](iceoryx2_link_tunnel::Tunnel) backend, and the zenoh carrier underneath. Upstream
//! calls that link a prototype; `docs/service.md` says what was measured with it.
//!
//! * [`ZenohSettings`] turns the few settings a deployment needs (mode, listen and connect
//!   endpoints, multicast scouting, or a whole zenoh configuration file) into a zenoh
//!   configuration.
//! * [`StreamTunnel`] opens primm's streams in the local iceoryx2 domain with primm's own
//!   quality of service, bridges them, and is driven by [`StreamTunnel::run`] until a shutdown
//!   flag is raised.
//! * [`StreamWatch`] counts, per stream, what was published here and sent to the peers and what
//!   arrived from them, with the gaps in what arrived; [`TunnelReport`] sums a run up.
//!
//! Samples cross as the bytes they are: both hosts need primm's payload layout (the `#[repr(C)]`
//! types of `primm-wire`, whose type names, sizes and alignments the tunnel compares) and the
//! same byte order.
//!
//! The crate is kept out of `primm-core`, and out of the `primm` binary unless its `tunnel`
//! feature is on: zenoh is a large dependency.

mod report;
mod settings;
mod tunnel;
mod watch;

pub use report::TunnelReport;
pub use settings::{ZenohConfigError, ZenohMode, ZenohSettings};
pub use tunnel::{StreamTunnel, TunnelOpenError, TunnelRunError, TunnelStatus};
pub use watch::{Sequenced, StreamCounts, StreamWatch};
