//! Two "hosts" on one machine for the tunnel's tests and benchmark: two iceoryx2 domains, each
//! with a `primm tunnel`, joined over zenoh on 127.0.0.1 with multicast scouting off.
#![allow(dead_code)]

use super::service::{unique_prefix, ChildGuard, Iceoryx2Domain};
use iceoryx2::node::Node;
use primm_service::catalog::{self, Ipc, ServiceNames};
use std::path::PathBuf;
use std::process::Stdio;
use std::time::{Duration, Instant};

/// Longest wait for anything in these tests; a hung tunnel fails the test instead of CI.
pub const HANG_GUARD: Duration = Duration::from_secs(60);

/// Two hosts with a tunnel each. Declared domains first, so that the tunnels (dropped first)
/// are gone before the domains' leftovers are removed.
pub struct TwoHosts {
    pub host_a: Iceoryx2Domain,
    pub host_b: Iceoryx2Domain,
    pub prefix: String,
    tunnels: Vec<(ChildGuard, PathBuf)>,
}

impl TwoHosts {
    /// Starts the tunnels of both hosts under a fresh service prefix and waits until they are
    /// connected to each other.
    pub fn start(test: &str) -> Self {
        Self::start_in_modes(test, "peer", "peer")
    }

    /// [`start`](Self::start) with host A's tunnel in zenoh mode `mode_a` (it listens) and host
    /// B's in `mode_b` (it connects).
    pub fn start_in_modes(test: &str, mode_a: &str, mode_b: &str) -> Self {
        let host_a = Iceoryx2Domain::new(&format!("{test}_a"));
        let host_b = Iceoryx2Domain::new(&format!("{test}_b"));
        let prefix = unique_prefix(test);
        // Host A's tunnel listens on a port the operating system picks (port 0) and names it
        // in its listening file; host B's connects there. No port is chosen by the test, so
        // none can be taken by another process in between.
        let listening = std::env::temp_dir().join(format!("{}tunnel.listening", host_a.name()));
        let _ = std::fs::remove_file(&listening);
        let mut endpoint = String::from("tcp/127.0.0.1:0");
        let mut tunnels = Vec::new();
        for (host, option, mode) in [(&host_a, "--listen", mode_a), (&host_b, "--connect", mode_b)] {
            let ready = std::env::temp_dir().join(format!("{}tunnel.ready", host.name()));
            let _ = std::fs::remove_file(&ready);
            let mut command = host.primm("warn");
            command
                .args(["tunnel", "--service-prefix", &prefix, "--mode", mode, "--multicast-scouting", "off"])
                .args([option, &endpoint])
                .arg("--ready-file")
                .arg(&ready);
            if option == "--listen" {
                command.arg("--listening-file").arg(&listening);
            }
            let child = command
                .stdout(Stdio::piped())
                .stderr(Stdio::null())
                .spawn()
                .expect("primm tunnel starts (built with the `tunnel` feature)");
            tunnels.push((ChildGuard(child), ready));
            if option == "--listen" {
                // zenoh in client mode gives up at once when nothing listens yet: start the
                // connecting side once the listening side says where it listens.
                let deadline = Instant::now() + HANG_GUARD;
                endpoint = loop {
                    if let Ok(text) = std::fs::read_to_string(&listening) {
                        break text
                            .lines()
                            .find(|line| line.starts_with("tcp/127.0.0.1:"))
                            .unwrap_or_else(|| {
                                panic!("no TCP endpoint on 127.0.0.1 in the listening file:\n{text}")
                            })
                            .to_owned();
                    }
                    assert!(tunnels[0].0.is_running(), "the listening tunnel exited before it listened");
                    assert!(
                        Instant::now() < deadline,
                        "the listening tunnel did not listen within {HANG_GUARD:?}"
                    );
                    std::thread::sleep(Duration::from_millis(20));
                };
            }
        }
        let deadline = Instant::now() + HANG_GUARD;
        for (tunnel, ready) in &mut tunnels {
            while !ready.exists() {
                assert!(tunnel.is_running(), "a tunnel exited before it connected");
                assert!(Instant::now() < deadline, "the tunnels did not connect within {HANG_GUARD:?}");
                std::thread::sleep(Duration::from_millis(20));
            }
        }
        Self { host_a, host_b, prefix, tunnels }
    }

    pub fn names(&self) -> ServiceNames {
        ServiceNames::new(&self.prefix)
    }

    /// A node on host A.
    pub fn node_a(&self, name: &str) -> Node<Ipc> {
        catalog::create_node_with(name, &catalog::iceoryx2_config_in(Some(self.host_a.name())).unwrap())
            .unwrap()
    }

    /// A node on host B.
    pub fn node_b(&self, name: &str) -> Node<Ipc> {
        catalog::create_node_with(name, &catalog::iceoryx2_config_in(Some(self.host_b.name())).unwrap())
            .unwrap()
    }

    /// Stops both tunnels (SIGINT) and returns their reports: host A's, then host B's.
    pub fn stop(mut self) -> (String, String) {
        let mut reports = Vec::new();
        for (tunnel, _) in self.tunnels.drain(..) {
            tunnel.signal(libc::SIGINT);
            let (status, report) = tunnel.wait(HANG_GUARD);
            assert!(status.success(), "a tunnel failed to stop cleanly ({status}):\n{report}");
            reports.push(report);
        }
        let leftovers: Vec<_> = self.host_a.resources().into_iter().chain(self.host_b.resources()).collect();
        assert!(leftovers.is_empty(), "the tunnels left {leftovers:?}");
        (reports.remove(0), reports.remove(0))
    }
}

/// The counters of `stream` in a tunnel report: sent, arrived, gaps, out of order.
pub fn counts(report: &str, stream: &str) -> [u64; 4] {
    let line = report
        .lines()
        .find(|line| line.split_whitespace().next().is_some_and(|name| name.ends_with(stream)))
        .unwrap_or_else(|| panic!("no line for {stream} in the tunnel report:\n{report}"));
    let numbers: Vec<u64> = line.split_whitespace().skip(1).map(|n| n.parse().unwrap()).collect();
    numbers.try_into().unwrap()
}
