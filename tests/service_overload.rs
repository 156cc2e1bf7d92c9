//! Overload: a publisher flooding a tracker that cannot keep up (here: one stopped with SIGSTOP,
//! the slowest tracker there is) never blocks, the tracker's backlog never exceeds its input
//! buffer, shared memory does not grow, and every frame is accounted for: the publisher's sent
//! and dropped frames add up to its input, the tracker's received and lost frames to what was
//! sent.

use crate::common;

use common::service::{spawn_collecting_stderr, unique_prefix, Iceoryx2Domain};
use primm_service::catalog::MEASUREMENTS_QOS;
use std::process::Stdio;
use std::time::Duration;

/// Guard against a hang (never a timing assertion).
const HANG_GUARD: Duration = Duration::from_secs(120);

/// The value of `key=` in the first line of `text` containing `marker`.
fn logged_count(text: &str, marker: &str, key: &str) -> u64 {
    let line = text
        .lines()
        .find(|line| line.contains(marker))
        .unwrap_or_else(|| panic!("no '{marker}' in:\n{text}"));
    let start =
        line.find(&format!("{key}=")).unwrap_or_else(|| panic!("no {key} in: {line}")) + key.len() + 1;
    line[start..].split(|c: char| !c.is_ascii_digit()).next().unwrap().parse().unwrap()
}

/// The number before `what` in the tracker's summary line `frames: N received, ...`.
fn summary_count(summary: &str, what: &str) -> u64 {
    let line =
        summary.lines().find(|line| line.starts_with("frames: ")).unwrap_or_else(|| panic!("{summary}"));
    let field = line.split([',', ';', ':']).find(|field| field.trim().ends_with(what)).unwrap();
    field.trim().split(' ').next().unwrap().parse().unwrap()
}

#[test]
fn a_flood_into_a_stalled_tracker_never_blocks_the_publisher_and_every_frame_is_accounted_for() {
    let domain = Iceoryx2Domain::new("flood");
    let prefix = unique_prefix("flood");
    let (serve, serve_log) = spawn_collecting_stderr(
        domain.primm("info").args(["serve", "--service-prefix", &prefix]).stdout(Stdio::piped()),
    );
    serve_log.wait_for("tracker serving", HANG_GUARD);
    let footprint = || -> Vec<(std::path::PathBuf, u64)> {
        domain
            .resources()
            .into_iter()
            .map(|path| (path.clone(), std::fs::metadata(&path).unwrap().len()))
            .collect()
    };
    let before_flood = footprint();
    serve.signal(libc::SIGSTOP);

    let (publisher, publisher_log) = spawn_collecting_stderr(
        domain
            .primm("info")
            .args(["publish", "--service-prefix", &prefix, "--scenario", "--duration-s", "60"])
            // iceoryx2 discards the frames of a publisher that disconnects before the tracker
            // took them: stay connected until the tracker has drained its buffer.
            .args(["--as-fast-as-possible", "--linger-s", "600"])
            .stdout(Stdio::null()),
    );
    publisher_log.wait_for("replaying", HANG_GUARD);
    let flood_starts = footprint();
    publisher_log.wait_for("replay finished", HANG_GUARD);
    let log = publisher_log.text();
    let frames = logged_count(&log, "replaying", "frames");
    let sent = logged_count(&log, "replay finished", "frames_sent");
    let dropped = logged_count(&log, "replay finished", "frames_dropped");
    let without_receiver = logged_count(&log, "replay finished", "frames_without_receiver");
    assert_eq!(sent + dropped, frames, "every frame is sent or counted as dropped");
    assert_eq!(without_receiver, 0, "the stalled tracker stays subscribed");
    let buffer = MEASUREMENTS_QOS.subscriber_buffer as u64;
    assert!(sent > 4 * buffer, "the flood ({sent} frames) overflows the input buffer ({buffer})");
    let flood_ends = footprint();
    assert_eq!(flood_ends, flood_starts, "shared memory does not grow during the flood");
    assert!(
        before_flood.iter().all(|file| flood_ends.contains(file)),
        "the tracker's segments keep their sizes"
    );

    serve.signal(libc::SIGCONT);
    serve.signal(libc::SIGINT);
    let (status, summary) = serve.wait(HANG_GUARD);
    assert!(status.success(), "{status}\n{}", serve_log.text());
    publisher.signal(libc::SIGINT);
    let (status, _) = publisher.wait(HANG_GUARD);
    assert!(
        status.success(),
        "the publisher finishes although nobody read during the flood: {status}\n{log}"
    );
    let received = summary_count(&summary, "received");
    let lost = summary_count(&summary, "lost");
    assert_eq!(received + lost, sent, "the tracker took or counted as lost every frame sent:\n{summary}");
    assert!(received <= buffer, "the backlog is bounded by the input buffer: {received} > {buffer}");
    assert!(received >= 1 && lost >= sent - buffer, "{summary}");
    assert!(domain.resources().is_empty(), "{:?}", domain.resources());
}
