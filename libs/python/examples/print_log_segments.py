#!/usr/bin/env python3
"""Prints the segment lists of an lcm-log that lcm-logger recorded of a running evldt system.

    print_log_segments.py LOG [CHANNEL]      (CHANNEL: LINES_CAM0 by default)

With the lcm Python module installed it reads through lcm.EventLog, else through evldt's own reader."""
import sys

import evldt

path = sys.argv[1]
channel = sys.argv[2] if len(sys.argv) > 2 else "LINES_CAM0"
try:
    import lcm
    messages = ((event.channel, event.timestamp, event.data) for event in lcm.EventLog(path, "r"))
except ImportError:
    messages = evldt.read_lcm_log(path)

lists = 0
for name, utime, data in messages:
    if name != channel:
        continue
    segments = evldt.segment_list_t.decode(data)
    lists += 1
    longest = max(segments.segments, key=lambda s: (s.x1 - s.x0) ** 2 + (s.y1 - s.y0) ** 2, default=None)
    summary = "" if longest is None else (
        f", longest id {longest.id}: ({longest.x0:.1f}, {longest.y0:.1f}) - ({longest.x1:.1f}, {longest.y1:.1f})")
    print(f"{utime}: {segments.num_segments} segments at event time {segments.t_us} us{summary}")
print(f"{lists} segment lists on {channel}")
