//! The programs' log output.

use crate::common;

use common::service::{spawn_collecting_stderr, unique_prefix, Iceoryx2Domain};
use std::process::Stdio;
use std::time::Duration;

#[test]
fn logs_written_to_a_pipe_carry_no_colour_codes() {
    let domain = Iceoryx2Domain::new("logging");
    let prefix = unique_prefix("logging");
    let (serve, log) = spawn_collecting_stderr(
        domain.primm("info").args(["serve", "--service-prefix", &prefix]).stdout(Stdio::null()),
    );
    log.wait_for("tracker serving", Duration::from_secs(120));
    serve.signal(libc::SIGINT);
    let (status, _) = serve.wait(Duration::from_secs(120));
    assert!(status.success());
    log.wait_for("tracker stopped", Duration::from_secs(10));
    let text = log.text();
    assert!(text.contains("INFO"), "the log has lines to check:\n{text}");
    assert!(!text.contains('\u{1b}'), "escape sequences in piped logs:\n{text:?}");
}
