//! Shared-memory hygiene: a clean exit of `primm serve`, `primm publish`, `primm subscribe` and
//! `primm demo` leaves nothing of its own behind, and after SIGKILL the next start removes the
//! dead processes' resources through iceoryx2 and says how many.
//!
//! Each test runs its processes in a private iceoryx2 domain ([`Iceoryx2Domain`]), so it counts
//! exactly its own files in `/dev/shm` and `/tmp/iceoryx2` while other tests run.

use crate::common;

use common::service::{spawn_collecting_stderr, unique_prefix, wait_until, ChildGuard, Iceoryx2Domain};
use std::collections::BTreeSet;
use std::path::PathBuf;
use std::process::Stdio;
use std::time::Duration;

/// Generous guard against a hang (never a timing assertion).
const HANG_GUARD: Duration = Duration::from_secs(120);

fn file_set(domain: &Iceoryx2Domain) -> BTreeSet<PathBuf> {
    domain.resources().into_iter().collect()
}

/// The files in `after` that were not in `before`.
fn left_behind(before: &BTreeSet<PathBuf>, after: &BTreeSet<PathBuf>) -> Vec<PathBuf> {
    after.difference(before).cloned().collect()
}

/// Whether every file in `files` is the segment of a publisher-subscriber connection.
fn only_connections(files: &[PathBuf]) -> bool {
    files.iter().all(|file| file.extension().is_some_and(|extension| extension == "connection"))
}

#[test]
fn clean_exits_of_serve_subscribe_and_publish_leave_nothing_of_their_own_in_shared_memory() {
    let domain = Iceoryx2Domain::new("clean");
    let prefix = unique_prefix("clean-exit");
    assert!(domain.resources().is_empty(), "a fresh domain holds nothing");

    let (serve, serve_log) = spawn_collecting_stderr(
        domain.primm("info").args(["serve", "--service-prefix", &prefix]).stdout(Stdio::piped()),
    );
    serve_log.wait_for("tracker serving", HANG_GUARD);
    let with_tracker = file_set(&domain);
    assert!(!with_tracker.is_empty(), "the tracker's segments are visible in its domain");

    let (subscriber, subscriber_log) = spawn_collecting_stderr(
        domain
            .primm("info")
            .args(["subscribe", "--service-prefix", &prefix, "--until-end", "--quiet"])
            .stdout(Stdio::piped()),
    );
    subscriber_log.wait_for("subscribed", HANG_GUARD);
    let with_subscriber = file_set(&domain);
    assert!(!left_behind(&with_tracker, &with_subscriber).is_empty(), "the subscriber adds its own files");

    let before_publisher = file_set(&domain);
    let publisher = ChildGuard(
        domain
            .primm("warn")
            .args(["publish", "--service-prefix", &prefix, "--scenario", "--duration-s", "2"])
            .args(["--as-fast-as-possible", "--max-in-flight", "4"])
            .spawn()
            .unwrap(),
    );
    let (status, _) = publisher.wait(HANG_GUARD);
    assert!(status.success(), "the publisher exits cleanly: {status}");
    // What stays are the segments of its connections to the tracker and the subscriber, which
    // are still running: iceoryx2 removes them with the receiving side (checked below).
    let leftovers = left_behind(&before_publisher, &file_set(&domain));
    assert!(only_connections(&leftovers), "the publisher left {leftovers:?}");

    let (status, _) = subscriber.wait(HANG_GUARD);
    assert!(status.success(), "the subscriber exits cleanly: {status}\n{}", subscriber_log.text());
    let leftovers = left_behind(&with_tracker, &file_set(&domain));
    assert!(only_connections(&leftovers), "the subscriber left {leftovers:?}");

    serve.signal(libc::SIGINT);
    let (status, _) = serve.wait(HANG_GUARD);
    assert!(status.success(), "the tracker exits cleanly: {status}\n{}", serve_log.text());
    let leftovers = domain.resources();
    assert!(leftovers.is_empty(), "the tracker left {leftovers:?}");
    assert!(domain.node_counters() <= 1, "one node counter per domain at most");
}

#[test]
fn after_sigkill_of_every_process_the_next_start_removes_the_dead_nodes_and_says_how_many() {
    let domain = Iceoryx2Domain::new("killed");
    let prefix = unique_prefix("sigkill-cleanup");
    let (serve, serve_log) = spawn_collecting_stderr(
        domain.primm("info").args(["serve", "--service-prefix", &prefix]).stdout(Stdio::null()),
    );
    serve_log.wait_for("tracker serving", HANG_GUARD);
    let (subscriber, subscriber_log) = spawn_collecting_stderr(
        domain
            .primm("info")
            .args(["subscribe", "--service-prefix", &prefix, "--quiet"])
            .stdout(Stdio::null()),
    );
    subscriber_log.wait_for("subscribed", HANG_GUARD);
    let (publisher, publisher_log) = spawn_collecting_stderr(
        domain
            .primm("info")
            .args(["publish", "--service-prefix", &prefix, "--scenario", "--duration-s", "30", "--loop"])
            .stdout(Stdio::null()),
    );
    publisher_log.wait_for("replaying", HANG_GUARD);
    for process in [&publisher, &subscriber, &serve] {
        process.signal(libc::SIGKILL);
    }
    for process in [publisher, subscriber, serve] {
        let (status, _) = process.wait(HANG_GUARD);
        assert!(!status.success());
    }
    assert!(!domain.resources().is_empty(), "processes killed with SIGKILL leave their resources");

    let (restarted, restarted_log) = spawn_collecting_stderr(
        domain.primm("info").args(["serve", "--service-prefix", &prefix]).stdout(Stdio::null()),
    );
    restarted_log.wait_for("tracker serving", HANG_GUARD);
    let log = restarted_log.text();
    assert!(log.contains("removed the resources of 3 dead iceoryx2 node(s)"), "{log}");
    assert!(!log.contains("could not remove"), "{log}");

    restarted.signal(libc::SIGINT);
    let (status, _) = restarted.wait(HANG_GUARD);
    assert!(status.success(), "{status}");
    let leftovers = domain.resources();
    assert!(leftovers.is_empty(), "after the restart and a clean exit, left: {leftovers:?}");
}

#[test]
fn the_demo_runs_end_to_end_prints_its_summary_and_leaves_nothing_in_shared_memory() {
    let domain = Iceoryx2Domain::new("demo");
    let demo = ChildGuard(
        domain
            .primm("warn")
            .args(["demo", "--duration-s", "3", "--speed", "3"])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap(),
    );
    let (status, output) = demo.wait(HANG_GUARD);
    assert!(status.success(), "{status}\n{output}");
    for expected in [
        "== subscriber (primm-subscriber) ==",
        "prior RMSE",
        "end_to_end",
        "demo finished: every frame tracked and answered over shared memory",
    ] {
        assert!(output.contains(expected), "'{expected}' missing from:\n{output}");
    }
    let leftovers = domain.resources();
    assert!(leftovers.is_empty(), "the demo left {leftovers:?}");
}

#[test]
fn the_demo_reports_a_tracker_that_cannot_start_with_its_error_and_exit_status() {
    let domain = Iceoryx2Domain::new("demo_fail");
    let missing = std::env::temp_dir().join(format!("{}missing.onnx", domain.name()));
    let (demo, demo_log) = spawn_collecting_stderr(
        domain
            .primm("warn")
            .args(["demo", "--method", "pr-imm", "--model"])
            .arg(&missing)
            .stdout(Stdio::null()),
    );
    let (status, _) = demo.wait(HANG_GUARD);
    assert!(!status.success());
    // Not "did not come up within 30 s": the demo saw the tracker exit and says why.
    demo_log.wait_for("the tracker (primm serve) exited (exit status: 1)", HANG_GUARD);
    let log = demo_log.text();
    assert!(log.contains(&missing.display().to_string()), "the tracker's own error names the file:\n{log}");
    assert!(!log.contains("did not come up"), "{log}");
    let leftovers = domain.resources();
    assert!(leftovers.is_empty(), "the failed demo left {leftovers:?}");
}

#[test]
fn a_demo_killed_with_sigkill_leaves_no_processes_and_the_next_start_cleans_up() {
    let domain = Iceoryx2Domain::new("demo_killed");
    let demo = ChildGuard(
        domain
            .primm("warn")
            .args(["demo", "--duration-s", "60", "--speed", "1"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    wait_until("the demo's processes come up", HANG_GUARD, || domain.processes() >= 3);
    // Kill it once it is running, not while a process is still creating its services: a
    // service a process dies in the middle of creating has no owner yet for the dead-node
    // cleanup to find. Running: its shared-memory resources stop changing for a second.
    let mut previous = domain.resources();
    wait_until("the demo's resources settle", HANG_GUARD, || {
        std::thread::sleep(Duration::from_secs(1));
        let now = domain.resources();
        let settled = now == previous && !now.is_empty();
        previous = now;
        settled
    });
    demo.signal(libc::SIGKILL);
    let (status, _) = demo.wait(HANG_GUARD);
    assert!(!status.success());
    // The kernel sends each child SIGTERM when the demo dies; they stop on their own.
    wait_until("the demo's children stop", HANG_GUARD, || domain.processes() == 0);

    // Whatever the demo itself held (its node, if it was killed while watching the services)
    // is removed by the next start.
    let (serve, serve_log) = spawn_collecting_stderr(
        domain.primm("info").args(["serve", "--service-prefix", "after-demo"]).stdout(Stdio::null()),
    );
    serve_log.wait_for("tracker serving", HANG_GUARD);
    serve.signal(libc::SIGINT);
    let (status, _) = serve.wait(HANG_GUARD);
    assert!(status.success());
    assert!(!serve_log.text().contains("could not remove"), "{}", serve_log.text());
    let leftovers = domain.resources();
    assert!(leftovers.is_empty(), "left: {leftovers:?}");
}
