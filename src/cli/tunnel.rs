//! `primm tunnel`: primm's streams across hosts, through the iceoryx2 link tunnel over zenoh
//! (built with the `tunnel` feature).
//!
//! Run one on every host, each in its own iceoryx2 domain: what is published on a stream on one
//! host is published on the same stream on the others, so the tracker, its sources and its
//! consumers may sit on different machines. `docs/service.md` shows a two-host setup.

use primm_service::catalog::{self, ConnectError, ServiceNames, ICEORYX2_DOMAIN_ENV, SERVICE_PREFIX_ENV};
use primm_service::ShutdownFlag;
use primm_tunnel::{StreamTunnel, TunnelOpenError, TunnelRunError, ZenohMode, ZenohSettings};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Arguments of `primm tunnel`.
#[derive(Debug, Clone, clap::Args)]
#[command(
    about = "Relay primm/measurements, primm/tracks and primm/latency to other hosts through the iceoryx2 link tunnel over zenoh"
)]
pub struct Args {
    /// Prefix of the service names (`PREFIX/primm/...`); the same on every host.
    #[arg(long, env = SERVICE_PREFIX_ENV, default_value = "")]
    pub service_prefix: String,
    /// zenoh configuration file (JSON5) to start from; the options below override it.
    #[arg(long, value_name = "FILE")]
    pub zenoh_config: Option<PathBuf>,
    /// zenoh mode: peer (default), router or client.
    #[arg(long, value_parser = parse_mode)]
    pub mode: Option<ZenohMode>,
    /// Endpoint to listen on, e.g. `tcp/0.0.0.0:7447` (repeatable).
    #[arg(long = "listen", value_name = "ENDPOINT")]
    pub listen: Vec<String>,
    /// Endpoint of another host's tunnel (or a zenoh router) to connect to, e.g.
    /// `tcp/192.168.1.20:7447` (repeatable).
    #[arg(long = "connect", value_name = "ENDPOINT")]
    pub connect: Vec<String>,
    /// Find other tunnels by UDP multicast scouting: on (zenoh's default) or off.
    #[arg(long, value_name = "on|off", value_parser = parse_on_off)]
    pub multicast_scouting: Option<bool>,
    /// Drop frames when zenoh's transmission queue is full (zenoh's default) instead of
    /// waiting for room.
    #[arg(long)]
    pub drop_when_congested: bool,
    /// Write this file once the tunnel is connected to another zenoh session (a peer, a router
    /// or, in router mode, a client); it holds the tunnel's zenoh id and is removed again when
    /// the tunnel stops.
    #[arg(long, value_name = "FILE")]
    pub ready_file: Option<PathBuf>,
    /// Write this file once the tunnel listens: one zenoh locator per line, e.g.
    /// `tcp/127.0.0.1:40123`, with the port the operating system chose for a `--listen`
    /// endpoint of port 0 (so that a script or a test needs no free port of its own); removed
    /// again when the tunnel stops.
    #[arg(long, value_name = "FILE")]
    pub listening_file: Option<PathBuf>,
    /// Print the counters to stderr this often (0: only at the end).
    #[arg(long, default_value_t = 0.0, value_name = "SECONDS")]
    pub stats_every_s: f64,
    /// Stop after this long (default: run until SIGINT or SIGTERM).
    #[arg(long, value_name = "SECONDS")]
    pub duration_s: Option<f64>,
}

/// Why `primm tunnel` failed.
#[derive(Debug, thiserror::Error)]
pub enum TunnelError {
    /// The SIGINT/SIGTERM handlers could not be installed.
    #[error("cannot install signal handlers: {0}")]
    Signals(std::io::Error),
    /// The iceoryx2 configuration is invalid (e.g. the domain in PRIMM_ICEORYX2_DOMAIN).
    #[error(transparent)]
    Connect(#[from] ConnectError),
    /// The tunnel could not be opened.
    #[error(transparent)]
    Open(#[from] TunnelOpenError),
    /// The tunnel stopped with an error.
    #[error(transparent)]
    Run(#[from] TunnelRunError),
    /// The ready file or the listening file could not be written.
    #[error("cannot write {path}: {source}")]
    ReadyFile {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

fn parse_mode(text: &str) -> Result<ZenohMode, String> {
    ZenohMode::from_id(text).ok_or_else(|| format!("`{text}` is not one of peer, router, client"))
}

fn parse_on_off(text: &str) -> Result<bool, String> {
    match text {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => Err(format!("`{text}` is neither `on` nor `off`")),
    }
}

/// Runs `primm tunnel`.
pub fn run(args: &Args) -> Result<(), TunnelError> {
    let shutdown = ShutdownFlag::on_signals().map_err(TunnelError::Signals)?;
    let names = ServiceNames::new(&args.service_prefix);
    let settings = ZenohSettings {
        config_file: args.zenoh_config.clone(),
        mode: args.mode,
        listen: args.listen.clone(),
        connect: args.connect.clone(),
        multicast_scouting: args.multicast_scouting,
        block_when_congested: !args.drop_when_congested,
    };
    let config = catalog::iceoryx2_config()?;
    let mut tunnel = StreamTunnel::open(&names, &config, &settings)?;
    // The link's own warnings (an arrival dropped by a full inbox, a bridge that fails) matter
    // here; iceoryx2's start-up chatter is over by now.
    iceoryx2::prelude::set_log_level_from_env_or(iceoryx2::prelude::LogLevel::Warn);
    let domain = std::env::var(ICEORYX2_DOMAIN_ENV).unwrap_or_else(|_| config.global.prefix.to_string());
    eprintln!(
        "primm tunnel: zenoh id {}, relaying {}, {} and {} of iceoryx2 domain '{domain}'",
        tunnel.zenoh_id(),
        names.measurements(),
        names.tracks(),
        names.latency()
    );

    if let Some(path) = &args.listening_file {
        // Written whole, then renamed: a reader never sees half of it.
        let mut text = tunnel.listening_on().join("\n");
        text.push('\n');
        let partial = PathBuf::from(format!("{}.partial", path.display()));
        std::fs::write(&partial, text)
            .and_then(|()| std::fs::rename(&partial, path))
            .map_err(|source| TunnelError::ReadyFile { path: path.clone(), source })?;
    }

    let started = Instant::now();
    let stats_every = (args.stats_every_s > 0.0).then(|| Duration::from_secs_f64(args.stats_every_s));
    let mut next_stats = stats_every.map(|every| started + every);
    let stop_at = args.duration_s.map(|seconds| started + Duration::from_secs_f64(seconds.max(0.0)));
    let zenoh_id = tunnel.zenoh_id();
    let mut ready_written = false;
    let mut ready_error = None;
    let report = tunnel.run(&shutdown, |status| {
        if !ready_written && status.peers > 0 {
            ready_written = true;
            if let Some(path) = &args.ready_file {
                if let Err(source) = std::fs::write(path, format!("{zenoh_id}\n")) {
                    ready_error = Some(TunnelError::ReadyFile { path: path.clone(), source });
                    shutdown.request();
                }
            }
            tracing::info!(peers = status.peers, "tunnel connected");
        }
        let now = Instant::now();
        if let (Some(due), Some(every)) = (next_stats, stats_every) {
            if now >= due {
                eprint!("{}", status.report);
                next_stats = Some(due + every);
            }
        }
        if stop_at.is_some_and(|stop| now >= stop) {
            shutdown.request();
        }
    });
    for path in [&args.ready_file, &args.listening_file].into_iter().flatten() {
        let _ = std::fs::remove_file(path);
    }
    if let Some(error) = ready_error {
        return Err(error);
    }
    print!("{}", report?);
    Ok(())
}
