//! `primm demo --hosts 2`: the demo spread over two "hosts" on one machine.
//!
//! Each host is an iceoryx2 domain of its own (separate shared-memory files, so the two see
//! nothing of each other), with a `primm tunnel`; the tunnels reach each other over zenoh on
//! 127.0.0.1 only, multicast scouting off. Host A runs the publisher and the tracker, host B the
//! subscriber, which therefore receives the tracks, the measurements (for the ground truth) and
//! the tracker's latency reports through the tunnels.

use super::{
    in_domain, quiet_logs, spawn_publisher, spawn_subscriber, spawn_tracker, stream_end_seen, wait_for_ports,
    wait_for_the_end, Args, DemoError, Managed, POLL_INTERVAL, READY_TIMEOUT, STOP_GRACE,
};
use primm_service::catalog;
use primm_service::ServiceNames;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// Once both tunnels have a peer, how long the demo lets zenoh exchange the subscriptions of
/// the streams before the first frame is sent.
const SETTLE: std::time::Duration = std::time::Duration::from_millis(500);

/// Runs the two-host demo.
pub(super) fn run(args: Args) -> Result<(), DemoError> {
    let exe = std::env::current_exe().map_err(DemoError::Executable)?;
    let pid = std::process::id();
    let prefix = format!("primm-demo-{pid}");
    let names = ServiceNames::new(&prefix);
    // The hosts' domains extend the demo's own (PRIMM_ICEORYX2_DOMAIN), so that whoever runs
    // the demo in a domain of its own finds the hosts' files under it too.
    let base = std::env::var(catalog::ICEORYX2_DOMAIN_ENV).unwrap_or_else(|_| format!("primm_demo_{pid}_"));
    let (domain_a, domain_b) = (format!("{base}host_a_"), format!("{base}host_b_"));
    let files = std::env::temp_dir();
    let file = |what: &str| files.join(format!("{prefix}-{what}"));
    let summary_path = file("summary.json");

    println!(
        "primm demo: {:.0} s scenario (seed {}) replayed at {}x; tracker method {}; services under '{prefix}/'",
        args.duration_s, args.seed, args.speed, args.method
    );
    println!("  host A (iceoryx2 domain '{domain_a}'): publisher, tracker, tunnel listening on 127.0.0.1");
    println!("  host B (iceoryx2 domain '{domain_b}'): subscriber, tunnel connecting to host A; zenoh multicast scouting off");

    let mut tracker = spawn_tracker(&exe, &prefix, Some(&domain_a), &args, file("tracker.log"))?;
    let mut subscriber =
        spawn_subscriber(&exe, &prefix, Some(&domain_b), &summary_path, &args, file("subscriber.log"))?;
    let node_a = catalog::create_node_with("primm-demo", &catalog::iceoryx2_config_in(Some(&domain_a))?)?;
    let node_b = catalog::create_node_with("primm-demo", &catalog::iceoryx2_config_in(Some(&domain_b))?)?;
    let tracks_a = catalog::tracks(&node_a, &names)?;
    let tracks_b = catalog::tracks(&node_b, &names)?;
    wait_for_ports(&tracks_a, &tracks_b, &mut tracker, &mut subscriber)?;

    let (tunnel_a, tunnel_b) = start_tunnels(&exe, &prefix, [&domain_a, &domain_b], &file)?;

    let publisher = spawn_publisher(&exe, &prefix, Some(&domain_a), &args, file("publisher.log"))?;
    let replay_s = args.duration_s / args.speed.max(1e-3);
    let outputs = wait_for_the_end(publisher, subscriber, tracker, replay_s);
    let tunnels = [stop_tunnel(tunnel_a), stop_tunnel(tunnel_b)];
    let complete = stream_end_seen(&summary_path);
    let hop = tunnel_hop(&summary_path);
    let _ = std::fs::remove_file(&summary_path);
    let outputs = outputs?;
    let [tunnel_a, tunnel_b] = tunnels;
    let (tunnel_a, tunnel_b) = (tunnel_a?, tunnel_b?);

    println!("\n== subscriber on host B (primm-subscriber) ==\n{}", outputs.subscriber);
    println!("== tracker on host A (primm serve) ==\n{}", outputs.tracker);
    println!("== tunnel of host A (primm tunnel) ==\n{tunnel_a}");
    println!("== tunnel of host B (primm tunnel) ==\n{tunnel_b}");
    if !outputs.logs.is_empty() {
        println!("== logs ==\n{}", outputs.logs);
    }
    match hop {
        Some(hop) => println!(
            "tunnel hop (tracker publishes on host A -> subscriber receives on host B, through both tunnels): \
             p50 {:.1} µs, p90 {:.1} µs, p99 {:.1} µs over {} track frames",
            hop.p50_us, hop.p90_us, hop.p99_us, hop.count
        ),
        None => println!("tunnel hop: no track frame reached host B"),
    }
    if !complete {
        return Err(DemoError::Incomplete);
    }
    super::print_latency_files(&args);
    println!("demo finished: every frame tracked on host A and answered on host B through the tunnel");
    Ok(())
}

/// Starts host A's tunnel listening on a port the operating system picks, then host B's
/// connecting to it; returns once both have a peer and zenoh had [`SETTLE`] to exchange the
/// subscriptions.
fn start_tunnels(
    exe: &Path,
    prefix: &str,
    [domain_a, domain_b]: [&str; 2],
    file: &dyn Fn(&str) -> PathBuf,
) -> Result<(Managed, Managed), DemoError> {
    let (ready_a, ready_b) = (file("tunnel-a.ready"), file("tunnel-b.ready"));
    let listening_a = file("tunnel-a.listening");
    let _ = std::fs::remove_file(&listening_a);
    // Port 0: the operating system picks a free port for host A's tunnel, which names it in
    // its listening file; host B connects there (no port is chosen here, so none can be taken
    // by someone else in between).
    let listening_option = listening_a.to_string_lossy().into_owned();
    let mut tunnel_a = spawn_tunnel(
        exe,
        prefix,
        domain_a,
        &["--listen", "tcp/127.0.0.1:0", "--listening-file", &listening_option],
        &ready_a,
        "the tunnel of host A",
        file("tunnel-a.log"),
    )?;
    let listen = wait_for_listening(&mut tunnel_a, &listening_a)?;
    println!("  host A's tunnel listens on {listen}");
    let mut tunnel_b = spawn_tunnel(
        exe,
        prefix,
        domain_b,
        &["--connect", &listen],
        &ready_b,
        "the tunnel of host B",
        file("tunnel-b.log"),
    )?;
    wait_for_tunnels([(&mut tunnel_a, &ready_a), (&mut tunnel_b, &ready_b)])?;
    std::thread::sleep(SETTLE);
    Ok((tunnel_a, tunnel_b))
}

/// Waits up to [`READY_TIMEOUT`] until `tunnel` has written its listening file, and returns
/// its TCP endpoint on 127.0.0.1; fails at once if the tunnel exits.
fn wait_for_listening(tunnel: &mut Managed, path: &Path) -> Result<String, DemoError> {
    let deadline = Instant::now() + READY_TIMEOUT;
    loop {
        if let Some(status) = tunnel.exited()? {
            return Err(tunnel.exited_error(status));
        }
        if let Ok(text) = std::fs::read_to_string(path) {
            return loopback_tcp_endpoint(&text)
                .ok_or_else(|| DemoError::ListeningEndpoint(text.trim().replace('\n', ", ")));
        }
        if Instant::now() >= deadline {
            return Err(DemoError::Timeout {
                what: tunnel.what,
                event: "listen",
                seconds: READY_TIMEOUT.as_secs(),
            });
        }
        std::thread::sleep(POLL_INTERVAL);
    }
}

/// The first `tcp/127.0.0.1:PORT` line of a tunnel's listening file.
pub(crate) fn loopback_tcp_endpoint(listening: &str) -> Option<String> {
    listening.lines().map(str::trim).find(|line| line.starts_with("tcp/127.0.0.1:")).map(str::to_owned)
}

/// Starts `primm tunnel` for `prefix` in `domain`, with the zenoh endpoint options `endpoints`,
/// on the loopback interface, writing `ready` once it has a peer.
fn spawn_tunnel(
    exe: &Path,
    prefix: &str,
    domain: &str,
    endpoints: &[&str],
    ready: &Path,
    what: &'static str,
    stderr_path: PathBuf,
) -> Result<Managed, DemoError> {
    let _ = std::fs::remove_file(ready);
    let mut command = Command::new(exe);
    command
        .args(["tunnel", "--service-prefix", prefix, "--mode", "peer", "--multicast-scouting", "off"])
        .args(endpoints)
        .arg("--ready-file")
        .arg(ready)
        .stdout(Stdio::piped());
    in_domain(&mut command, Some(domain));
    quiet_logs(&mut command);
    Managed::spawn(what, &mut command, stderr_path)
}

/// Waits up to [`READY_TIMEOUT`] until every tunnel has written its ready file; fails at once
/// if one exits.
fn wait_for_tunnels<const N: usize>(mut tunnels: [(&mut Managed, &PathBuf); N]) -> Result<(), DemoError> {
    let deadline = Instant::now() + READY_TIMEOUT;
    loop {
        let mut waiting_for = None;
        for (tunnel, ready) in tunnels.iter_mut() {
            if let Some(status) = tunnel.exited()? {
                return Err(tunnel.exited_error(status));
            }
            if !ready.exists() {
                waiting_for = Some(tunnel.what);
            }
        }
        let Some(what) = waiting_for else { return Ok(()) };
        if Instant::now() >= deadline {
            return Err(DemoError::Timeout { what, event: "connect", seconds: READY_TIMEOUT.as_secs() });
        }
        std::thread::sleep(POLL_INTERVAL);
    }
}

/// Stops a tunnel (SIGINT) and returns its report.
fn stop_tunnel(mut tunnel: Managed) -> Result<String, DemoError> {
    if let Some(status) = tunnel.exited()? {
        return Err(tunnel.exited_error(status));
    }
    tunnel.interrupt();
    match tunnel.wait(STOP_GRACE)? {
        Some(status) if status.success() => Ok(tunnel.output().0),
        Some(status) => Err(tunnel.exited_error(status)),
        None => Err(DemoError::Timeout { what: tunnel.what, event: "stop", seconds: STOP_GRACE.as_secs() }),
    }
}

/// Percentiles of the tunnel hop, µs.
struct Hop {
    count: u64,
    p50_us: f64,
    p90_us: f64,
    p99_us: f64,
}

/// The tunnel hop from the subscriber's summary: its delivery latency, from the tracker's send
/// on host A to its own receive on host B (one clock: both "hosts" are this machine).
fn tunnel_hop(summary_path: &Path) -> Option<Hop> {
    let text = std::fs::read_to_string(summary_path).ok()?;
    let json: serde_json::Value = serde_json::from_str(&text).ok()?;
    let row = json.get("delivery_latency")?;
    let field = |name: &str| row.get(name).and_then(serde_json::Value::as_u64);
    let us = |name: &str| field(name).map(|ns| ns as f64 / 1000.0);
    Some(Hop { count: field("count")?, p50_us: us("p50_ns")?, p90_us: us("p90_ns")?, p99_us: us("p99_ns")? })
}
