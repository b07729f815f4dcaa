#!/usr/bin/env python3
"""Prints the segments a running evldt-lines publishes (needs the lcm Python module).

    subscribe_lines.py [CAMERA] [LCM_URL]     (CAMERA: cam0; LCM_URL: LCM's default)"""
import sys

import lcm

import evldt

camera = sys.argv[1] if len(sys.argv) > 1 else "cam0"
channel = "LINES_" + camera.upper()


def on_segments(channel_name, data):
    segments = evldt.segment_list_t.decode(data)
    good = sum(1 for s in segments.segments if s.status == evldt.line_segment_t.STATUS_GOOD_TRACK)
    latency_ms = (segments.utime - segments.newest_batch_utime) / 1e3
    print(f"{channel_name}: {segments.num_segments} segments ({good} tracked well) at event time {segments.t_us} us, "
          f"{latency_ms:.1f} ms after its newest batch")


bus = lcm.LCM(sys.argv[2]) if len(sys.argv) > 2 else lcm.LCM()
bus.subscribe(channel, on_segments)
print(f"listening on {channel}; Ctrl-C ends")
try:
    while True:
        bus.handle()
except KeyboardInterrupt:
    pass
