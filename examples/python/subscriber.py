#!/usr/bin/env python3
"""Reads the tracks the primm tracker publishes on ``primm/tracks`` with the iceoryx2 Python
package and prints them.

Install the wire types first (once, into the Python you run this with):

    pip install "crates/primm-wire/python[subscribe]"   # primm_wire and iceoryx2==0.10.0

The samples are read in place from shared memory through the ctypes declarations of the
``primm_wire`` module. The script sleeps on the event service of the same name until the tracker
notifies, and opens the service with the same QoS as every primm program.

    python3 examples/python/subscriber.py [--service-prefix PREFIX] [--frames N] [--json] [--record FILE]

With ``--json`` it prints one JSON object per track frame instead of a table. With ``--record
FILE`` it also appends every track frame to FILE as it lies in shared memory (217 168 bytes each,
the layout of ``primm_track_frame`` in ``primm_wire.h``); ``examples/c/subscriber.c`` reads such
a file with that header alone. Like every primm program it works in the iceoryx2 domain that
``PRIMM_ICEORYX2_DOMAIN`` names (iceoryx2's default domain when unset), so it also reads the
tracks a ``primm tunnel`` brings from another host.
"""

import argparse
import ctypes
import json
import os
import sys

from primm_wire import CLASS_NAMES, QOS, STATUS_NAMES, TRACKS, TrackFrame, service_name

# The iceoryx2 package, imported in main() so that --help works without it.
iox2 = None


def iceoryx2_config():
    """iceoryx2's global configuration in the domain PRIMM_ICEORYX2_DOMAIN names, if set."""
    config = iox2.config.global_config()
    domain = os.environ.get("PRIMM_ICEORYX2_DOMAIN")
    if domain:
        config.global_cfg.prefix = iox2.FileName.new(domain)
    return config


def open_tracks(node, prefix):
    name = iox2.ServiceName.new(service_name(TRACKS, prefix))
    qos = QOS[TRACKS]
    data = (
        node.service_builder(name)
        .publish_subscribe(TrackFrame)
        .enable_safe_overflow(True)
        .subscriber_max_buffer_size(qos["subscriber_buffer"])
        .history_size(qos["history"])
        .max_publishers(qos["max_publishers"])
        .max_subscribers(qos["max_subscribers"])
        .subscriber_max_borrowed_samples(qos["max_borrowed"])
        .open_or_create()
    )
    events = node.service_builder(name).event().open_or_create()
    return data, events


def frame_record(frame):
    tracks = []
    for track in frame.valid_tracks():
        tracks.append(
            {
                "id": track.id,
                "class": CLASS_NAMES.get(track.class_code, str(track.class_code)),
                "confirmed": track.status in (1, 2),  # confirmed or coasting
                "x_m": track.x_m,
                "y_m": track.y_m,
                "vx_mps": track.vx_mps,
                "vy_mps": track.vy_mps,
                "mode_probabilities": list(track.mode_probabilities),
                "measurement_index": track.measurement_index,
                "gt_id": track.gt_id,
            }
        )
    return {
        "input_sequence": frame.input_sequence,
        "source_frame": frame.source_frame,
        "sensor_timestamp_s": frame.sensor_timestamp_s,
        "status": STATUS_NAMES.get(frame.status, str(frame.status)),
        "flags": frame.flags,
        "tracks": tracks,
    }


def print_table(record):
    print(
        f"frame {record['source_frame']} seq {record['input_sequence']} t {record['sensor_timestamp_s']:.3f} s "
        f"{record['status']}: {len(record['tracks'])} tracks"
    )
    for track in record["tracks"]:
        if track["confirmed"]:
            pr, cv, ca, ct = track["mode_probabilities"]
            print(
                f"  {track['id']:>5} {track['class']:<10} x {track['x_m']:8.2f} y {track['y_m']:8.2f} "
                f"v ({track['vx_mps']:6.2f}, {track['vy_mps']:6.2f})  mu PR {pr:.2f} CV {cv:.2f} CA {ca:.2f} CT {ct:.2f}"
            )


def main():
    parser = argparse.ArgumentParser(description=" ".join(__doc__.split("\n\n")[0].split()))
    parser.add_argument("--service-prefix", default=os.environ.get("PRIMM_SERVICE_PREFIX", ""))
    parser.add_argument("--frames", type=int, default=0, help="exit after this many track frames (0: never)")
    parser.add_argument("--timeout-s", type=float, default=0.0, help="exit after this long without a frame (0: never)")
    parser.add_argument("--json", action="store_true", help="one JSON object per track frame")
    parser.add_argument(
        "--record",
        metavar="FILE",
        help="also append every track frame to FILE as it lies in shared memory (examples/c/subscriber.c reads it)",
    )
    args = parser.parse_args()

    global iox2
    try:
        import iceoryx2
    except ImportError:
        print(
            'subscriber.py: the iceoryx2 Python package is missing: pip install "crates/primm-wire/python[subscribe]"',
            file=sys.stderr,
        )
        return 2
    iox2 = iceoryx2
    record_file = open(args.record, "ab") if args.record else None

    iox2.set_log_level_from_env_or(iox2.LogLevel.Error)
    node = iox2.NodeBuilder.new().config(iceoryx2_config()).create(iox2.ServiceType.Ipc)
    data, events = open_tracks(node, args.service_prefix)
    subscriber = data.subscriber_builder().create()
    listener = events.listener_builder().create()
    print(f"listening on {service_name(TRACKS, args.service_prefix)}", file=sys.stderr, flush=True)

    received = 0
    idle_s = 0.0
    wait = iox2.Duration.from_millis(100)
    while args.frames == 0 or received < args.frames:
        listener.timed_wait(wait)
        got_any = False
        while True:
            sample = subscriber.receive()
            if sample is None:
                break
            got_any = True
            frame = sample.payload().contents
            record = frame_record(frame)
            if record_file is not None:
                record_file.write(ctypes.string_at(ctypes.addressof(frame), ctypes.sizeof(TrackFrame)))
                record_file.flush()
            sample.delete()
            received += 1
            if args.json:
                print(json.dumps(record), flush=True)
            else:
                print_table(record)
            if args.frames and received >= args.frames:
                break
        idle_s = 0.0 if got_any else idle_s + 0.1
        if args.timeout_s and idle_s >= args.timeout_s:
            break
    if record_file is not None:
        record_file.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
