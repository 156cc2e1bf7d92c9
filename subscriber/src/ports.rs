//! The subscriber's iceoryx2 ports and how it waits on them and reads them.

use crate::viewer::Viewer;
use crate::{Args, SubscribeError};
use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::CallbackProgression;
use iceoryx2::waitset::{WaitSet, WaitSetGuard};
use primm_ipc::catalog::{self, Ipc};
use primm_ipc::ServiceNames;
use primm_wire::{LatencyReport, MeasurementFrame, TrackFrame, TRACK_FLAG_STREAM_END};
use std::time::{Duration, Instant};

/// The subscriber's ports: tracks, latency reports and (for the accuracy view) measurements.
pub(crate) struct Ports {
    tracks: Subscriber<Ipc, TrackFrame, ()>,
    track_listener: Listener<Ipc>,
    latency: Subscriber<Ipc, LatencyReport, ()>,
    latency_listener: Listener<Ipc>,
    pub(crate) truth: Option<(Subscriber<Ipc, MeasurementFrame, ()>, Listener<Ipc>)>,
}

impl Ports {
    /// Opens the streams and their ports; the measurements' only when `truth`.
    pub(crate) fn open(node: &Node<Ipc>, names: &ServiceNames, truth: bool) -> Result<Self, SubscribeError> {
        let tracks = catalog::tracks(node, names)?;
        let latency = catalog::latency(node, names)?;
        let track_subscriber = tracks.subscriber()?;
        let track_listener = tracks.listener()?;
        let latency_subscriber = latency.subscriber()?;
        let latency_listener = latency.listener()?;
        let truth = if truth {
            let measurements = catalog::measurements(node, names)?;
            Some((measurements.subscriber()?, measurements.listener()?))
        } else {
            None
        };
        Ok(Self {
            tracks: track_subscriber,
            track_listener,
            latency: latency_subscriber,
            latency_listener,
            truth,
        })
    }

    /// Attaches every listener to `waitset`.
    pub(crate) fn attach<'w, 'a>(
        &'a self,
        waitset: &'w WaitSet<Ipc>,
    ) -> Result<Vec<WaitSetGuard<'w, 'a, Ipc>>, SubscribeError> {
        let mut guards = Vec::new();
        guards
            .push(waitset.attach_notification(&self.track_listener).map_err(SubscribeError::WaitSetAttach)?);
        guards.push(
            waitset.attach_notification(&self.latency_listener).map_err(SubscribeError::WaitSetAttach)?,
        );
        if let Some((_, listener)) = &self.truth {
            guards.push(waitset.attach_notification(listener).map_err(SubscribeError::WaitSetAttach)?);
        }
        Ok(guards)
    }

    /// Sleeps in `waitset` until a notification or the tick, then consumes the notifications
    /// (the data is read by [`receive`](Self::receive)).
    pub(crate) fn wait(&self, waitset: &WaitSet<Ipc>) -> Result<(), SubscribeError> {
        waitset
            .wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, Duration::from_millis(200))
            .map_err(SubscribeError::WaitSetRun)?;
        let _ = self.track_listener.try_wait(|_| {});
        let _ = self.latency_listener.try_wait(|_| {});
        if let Some((_, listener)) = &self.truth {
            let _ = listener.try_wait(|_| {});
        }
        Ok(())
    }

    /// Hands every waiting sample to `viewer`: measurements first (a track frame's measurement
    /// frame was sent before it), then track frames, then latency reports. Returns whether the
    /// subscriber is done (`--frames` reached, or the end of the stream with `--until-end`).
    pub(crate) fn receive(&self, viewer: &mut Viewer, args: &Args) -> Result<bool, SubscribeError> {
        if let (Some((subscriber, _)), Some(accuracy)) = (&self.truth, viewer.accuracy.as_mut()) {
            while let Some(sample) = subscriber.receive().map_err(SubscribeError::Receive)? {
                accuracy.add_measurements(&sample);
            }
        }
        let mut done = false;
        while let Some(sample) = self.tracks.receive().map_err(SubscribeError::Receive)? {
            viewer.on_tracks(&sample)?;
            if args.frames.is_some_and(|limit| viewer.summary.track_frames >= limit)
                || (args.until_end && sample.flags & TRACK_FLAG_STREAM_END != 0)
            {
                done = true;
                break;
            }
        }
        while let Some(sample) = self.latency.receive().map_err(SubscribeError::Receive)? {
            viewer.last_report = Some(*sample);
        }
        Ok(done)
    }

    /// The tracker may send its latency report right after the last frame: takes it if it comes
    /// within 100 ms.
    pub(crate) fn take_late_latency_report(&self, viewer: &mut Viewer) -> Result<(), SubscribeError> {
        let deadline = Instant::now() + Duration::from_millis(100);
        while Instant::now() < deadline {
            match self.latency.receive().map_err(SubscribeError::Receive)? {
                Some(sample) => viewer.last_report = Some(*sample),
                None => std::thread::sleep(Duration::from_millis(5)),
            }
        }
        Ok(())
    }
}
