//! `--latency-out`: the HdrHistogram files and plots of the service, checked from outside.
//!
//! - `primm demo --latency-out DIR` leaves `.hlog`, `.hgrm` per stage and the two plots; the
//!   Python `hdrhistogram` package (`tools/hdr_crosscheck.py`, an implementation independent of
//!   primm's) decodes every interval log and agrees with the `.hgrm` files and with the latency
//!   tables primm printed. Needs `pip install -r tools/requirements-test.txt`.
//! - `primm latency-plot` draws two logs into one SVG and refuses a file that is not a log.
//! - The coordinated-omission correction: frames stamped as due 50 ms before they were sent
//!   show at least those 50 ms in `end_to_end_corrected` and not in `end_to_end`.

use crate::common;

use common::service::{spawn_serve, unique_prefix, Iceoryx2Domain, TestClient};
use hdrhistogram::Histogram;
use primm_service::clock::monotonic_ns;
use primm_service::latency_files::read_interval_log;
use primm_service::ServiceNames;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

/// A fresh directory under the system's temporary directory.
fn scratch_directory(name: &str) -> PathBuf {
    let directory =
        std::env::temp_dir().join(format!("primm-{name}-{}-{}", std::process::id(), monotonic_ns()));
    std::fs::create_dir_all(&directory).unwrap();
    directory
}

const QUANTILES: [f64; 5] = [0.0, 0.5, 0.9, 0.99, 1.0];

fn quantiles(histogram: &Histogram<u64>) -> Vec<u64> {
    QUANTILES.iter().map(|&q| histogram.value_at_quantile(q)).collect()
}

fn svg_with(path: &Path, texts: &[&str]) {
    let svg = std::fs::read_to_string(path).unwrap_or_else(|error| panic!("{}: {error}", path.display()));
    assert!(svg.starts_with("<svg"), "{} is no SVG", path.display());
    for text in texts {
        assert!(svg.contains(text), "{} lacks `{text}`", path.display());
    }
}

#[test]
fn demo_latency_files_agree_with_an_independent_decoder_and_with_primm_s_tables() {
    let check = Command::new("python3").args(["-c", "import hdrh"]).output().expect("python3 runs");
    assert!(
        check.status.success(),
        "the Python hdrhistogram package is missing: pip install -r tools/requirements-test.txt"
    );
    let domain = Iceoryx2Domain::new("latency-files");
    let directory = scratch_directory("latency-out");
    let output = domain
        .primm("warn")
        .args(["demo", "--duration-s", "6", "--speed", "3", "--latency-interval-s", "0.5", "--latency-out"])
        .arg(&directory)
        .output()
        .expect("primm demo runs");
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(output.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&output.stderr));
    assert!(stdout.contains(&format!("latency files in {}", directory.display())), "{stdout}");

    let tracker = ["validate", "associate", "receive_to_publish", "end_to_end", "end_to_end_corrected"];
    let subscriber =
        ["publisher_to_subscriber", "publisher_to_subscriber_corrected", "tracker_to_subscriber"];
    for stage in tracker.iter().chain(&subscriber) {
        for extension in ["hlog", "hgrm"] {
            let path = directory.join(format!("{stage}.{extension}"));
            assert!(path.is_file(), "{} missing; demo printed:\n{stdout}", path.display());
        }
    }
    svg_with(
        &directory.join("tracker.svg"),
        &["receive_to_publish", "end_to_end_corrected", "99.99%", "90%"],
    );
    svg_with(&directory.join("subscriber.svg"), &["publisher_to_subscriber_corrected", "99.9%"]);

    // The publisher stamps each frame with the time it was due and sends it at or after that
    // time: every corrected latency is at least the uncorrected one, for the same samples.
    for (measured, corrected) in [
        ("end_to_end", "end_to_end_corrected"),
        ("publisher_to_subscriber", "publisher_to_subscriber_corrected"),
    ] {
        let measured = read_interval_log(&directory.join(format!("{measured}.hlog"))).unwrap();
        let corrected = read_interval_log(&directory.join(format!("{corrected}.hlog"))).unwrap();
        assert!(measured.len() > 20, "{} samples", measured.len());
        assert_eq!(measured.len(), corrected.len());
        for (plain, late) in quantiles(&measured).into_iter().zip(quantiles(&corrected)) {
            assert!(late >= plain, "corrected {late} ns below uncorrected {plain} ns");
        }
    }

    let tables = directory.join("demo-output.txt");
    std::fs::write(&tables, &stdout).unwrap();
    let crosscheck = Command::new("python3")
        .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/tools/hdr_crosscheck.py"))
        .arg(&directory)
        .arg("--tables")
        .arg(&tables)
        .output()
        .expect("python3 runs");
    let report = String::from_utf8_lossy(&crosscheck.stdout).into_owned();
    assert!(crosscheck.status.success(), "{report}\n{}", String::from_utf8_lossy(&crosscheck.stderr));
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    let logs = report["logs"].as_array().unwrap();
    assert_eq!(logs.len(), 13, "10 tracker stages and 3 subscriber latencies: {report}");
    assert!(logs.iter().all(|log| log["intervals"].as_u64().unwrap() >= 2), "{report}");
    let checked: Vec<&str> = report["table_rows_checked"]
        .as_array()
        .unwrap()
        .iter()
        .map(|row| row["stage"].as_str().unwrap())
        .collect();
    for stage in ["receive_to_publish", "end_to_end_corrected", "publisher_to_subscriber"] {
        assert!(checked.contains(&stage), "{stage} not compared with primm's table: {report}");
    }

    // Two runs' logs (here two stages of one run) in one comparison plot.
    let compare = directory.join("compare.svg");
    let plotted = Command::new(env!("CARGO_BIN_EXE_primm"))
        .arg("latency-plot")
        .arg(directory.join("end_to_end.hlog"))
        .arg(directory.join("end_to_end_corrected.hlog"))
        .args(["--label", "as sent", "--output"])
        .arg(&compare)
        .output()
        .unwrap();
    assert!(plotted.status.success(), "{}", String::from_utf8_lossy(&plotted.stderr));
    svg_with(&compare, &["as sent", "end_to_end_corrected", "99.99%"]);
    let printed = String::from_utf8_lossy(&plotted.stdout);
    assert!(printed.contains("as sent") && printed.contains("end_to_end_corrected"), "{printed}");

    let refused = Command::new(env!("CARGO_BIN_EXE_primm"))
        .arg("latency-plot")
        .arg(&tables)
        .arg("--output")
        .arg(directory.join("never.svg"))
        .output()
        .unwrap();
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("not an HdrHistogram interval log"));
    let _ = std::fs::remove_dir_all(&directory);
}

#[test]
fn frames_sent_behind_their_schedule_show_the_delay_only_in_the_corrected_latency() {
    const BEHIND_NS: u64 = 50_000_000;
    let prefix = unique_prefix("coordinated-omission");
    let client = TestClient::new(&ServiceNames::new(&prefix));
    let directory = scratch_directory("coordinated-omission");
    let directory_text = directory.display().to_string();
    let serve = spawn_serve(&prefix, &["--latency-out", &directory_text]);
    client.wait_for_tracker(Duration::from_secs(30));
    let frames = common::scene_frames(&common::lanes(8), 40, 0.05, 0.2, 5);
    for (k, frame) in frames.iter().enumerate() {
        // Due 50 ms before the send: a publisher that stalled and is catching up.
        client.send_scheduled(frame, k as u64, 0, monotonic_ns() - BEHIND_NS);
        client.next_answer(Duration::from_secs(10), |_| ()).expect("the tracker answers");
    }
    serve.signal(libc::SIGINT);
    let (status, stdout) = serve.wait(Duration::from_secs(10));
    assert!(status.success(), "{stdout}");
    assert!(stdout.contains("end_to_end_corrected"), "the table names the corrected latency:\n{stdout}");
    let measured = read_interval_log(&directory.join("end_to_end.hlog")).unwrap();
    let corrected = read_interval_log(&directory.join("end_to_end_corrected.hlog")).unwrap();
    assert_eq!(measured.len(), 40);
    assert_eq!(corrected.len(), 40);
    // Each corrected sample is its uncorrected one plus at least 50 ms, so every quantile is
    // (to the histogram's 0.1 % resolution).
    for (plain, late) in quantiles(&measured).into_iter().zip(quantiles(&corrected)) {
        assert!(
            late as f64 >= (plain + BEHIND_NS) as f64 * 0.999,
            "corrected {late} ns, uncorrected {plain} ns"
        );
    }
    let hgrm = std::fs::read_to_string(directory.join("end_to_end_corrected.hgrm")).unwrap();
    assert!(hgrm.contains("corrected for coordinated omission"), "{hgrm}");
    assert!(hgrm.contains("Total count    =           40"), "{hgrm}");
    let _ = std::fs::remove_dir_all(&directory);
}
