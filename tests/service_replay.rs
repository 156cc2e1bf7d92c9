//! A replay through the `primm serve` process comes back frame for frame, with the same tracks
//! as the library's `Tracker` run offline on the same wire frames.

mod common;

use common::service::{spawn_serve, unique_prefix, wire_frame, TestClient};
use primm::config::Config;
use primm::mode::Method;
use primm::service::ServiceNames;
use primm::tracker::Tracker;
use primm::wire::{FrameStatus, WireTrack};
use std::time::Duration;

#[test]
fn every_frame_comes_back_in_order_with_the_offline_tracks() {
    let prefix = unique_prefix("replay");
    let names = ServiceNames::new(&prefix);
    let client = TestClient::new(&names);
    let serve = spawn_serve(&prefix, &["--method", "imm"]);
    client.wait_for_tracker(Duration::from_secs(20));

    let frames = common::scene_frames(&common::lanes(12), 200, 0.05, 0.2, 5);
    let mut offline = Tracker::new(Config::default().with_modes(Method::Imm.modes())).unwrap();
    let mut confirmed_seen = 0;
    for (k, frame) in frames.iter().enumerate() {
        let sequence = k as u64;
        client.send(frame, sequence, 0);
        let expected: Vec<WireTrack> = {
            let wire = wire_frame(frame, sequence);
            offline.step(&*wire).unwrap().iter().map(WireTrack::from_output).collect()
        };
        let (answer_sequence, status, tracks) = client
            .next_answer(Duration::from_secs(10), |answer| {
                (answer.input_sequence, answer.frame_status(), answer.valid_tracks().to_vec())
            })
            .unwrap_or_else(|| panic!("no answer to frame {k}"));
        assert_eq!(answer_sequence, sequence);
        assert_eq!(status, Some(FrameStatus::Tracked));
        assert_eq!(tracks, expected, "frame {k}: served tracks differ from the offline run");
        confirmed_seen = confirmed_seen.max(tracks.iter().filter(|t| t.status == 1).count());
    }
    assert_eq!(confirmed_seen, 12, "every lane object is confirmed");

    serve.signal(libc::SIGINT);
    let (status, stdout) = serve.wait(Duration::from_secs(10));
    assert!(status.success(), "{status}: {stdout}");
    assert!(stdout.contains("frames: 200 received, 200 tracked, 0 rejected, 0 lost"), "{stdout}");
    for stage in ["validate", "predict", "associate", "update", "report", "publish", "receive_to_publish", "end_to_end"] {
        assert!(stdout.contains(stage), "the final latency table lacks {stage}: {stdout}");
    }
}
