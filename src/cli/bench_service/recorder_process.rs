//! `bench-service --record FILE`: `primm record` running beside the tracker for the whole
//! trial, to measure what recording costs and whether the recorder keeps up.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// How long the recorder may take to subscribe, and to close its file once asked to stop.
const RECORDER_TIMEOUT: Duration = Duration::from_secs(20);

/// A `primm record` child.
pub struct RecorderProcess {
    child: Child,
}

impl RecorderProcess {
    /// Starts `primm record` under `prefix` into `output`; returns once it has subscribed to
    /// the track stream (`subscribers()` counts it).
    pub fn start(
        exe: &Path,
        prefix: &str,
        output: &Path,
        subscribers: impl Fn() -> usize,
    ) -> Result<Self, String> {
        let before = subscribers();
        let child = Command::new(exe)
            .args(["record", "--service-prefix", prefix, "--output"])
            .arg(output)
            .env("RUST_LOG", "warn")
            .stdout(Stdio::piped())
            .spawn()
            .map_err(|error| format!("cannot start primm record: {error}"))?;
        let mut recorder = Self { child };
        let deadline = Instant::now() + RECORDER_TIMEOUT;
        while subscribers() <= before {
            if Instant::now() >= deadline || matches!(recorder.child.try_wait(), Ok(Some(_))) {
                let _ = recorder.child.kill();
                return Err("primm record did not subscribe".to_owned());
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        Ok(recorder)
    }

    /// Stops it (SIGINT) and returns its summary.
    pub fn finish(mut self) -> Result<String, String> {
        // SAFETY: sending a signal to our own child by its pid has no memory-safety concerns.
        unsafe {
            libc::kill(self.child.id() as libc::pid_t, libc::SIGINT);
        }
        let deadline = Instant::now() + RECORDER_TIMEOUT;
        loop {
            if let Some(status) = self.child.try_wait().map_err(|error| error.to_string())? {
                let mut text = String::new();
                if let Some(mut pipe) = self.child.stdout.take() {
                    use std::io::Read;
                    let _ = pipe.read_to_string(&mut text);
                }
                return if status.success() {
                    Ok(text)
                } else {
                    Err(format!("primm record exited ({status}): {text}"))
                };
            }
            if Instant::now() >= deadline {
                let _ = self.child.kill();
                return Err("primm record did not stop".to_owned());
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for RecorderProcess {
    fn drop(&mut self) {
        if matches!(self.child.try_wait(), Ok(None)) {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}
