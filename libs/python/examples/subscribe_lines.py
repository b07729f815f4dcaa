#!/usr/bin/env python3
"""Prints the segments and whole lines a running evldt-lines publishes, through evldt's own
subscriber (no lcm Python module needed).

    subscribe_lines.py [CAMERA] [LCM_URL] [LISTS]     (cam0; LCM's default URL; 0: until Ctrl-C)"""
import sys

import evldt

camera = sys.argv[1] if len(sys.argv) > 1 else "cam0"
url = sys.argv[2] if len(sys.argv) > 2 else ""
wanted = int(sys.argv[3]) if len(sys.argv) > 3 else 0

subscriber = evldt.Subscriber(camera, url)
print(f"ready: listening to camera {camera}; Ctrl-C ends", flush=True)
received = 0
try:
    for lines in subscriber.lists():
        kind = "whole lines" if lines.whole_lines else "segments"
        good = int((lines.lines["status"] == evldt.STATUS_NAMES.index("good")).sum()) if not lines.whole_lines else 0
        print(f"{lines.camera}: {len(lines.lines)} {kind} at event time {lines.t_us} us"
              + (f" ({good} tracked well)" if not lines.whole_lines else ""), flush=True)
        for line in lines.lines[:3]:
            print(f"  id {line['id']}: ({line['x0']:.1f}, {line['y0']:.1f}) - ({line['x1']:.1f}, {line['y1']:.1f})", flush=True)
        received += 1
        if wanted and received >= wanted:
            break
except KeyboardInterrupt:
    pass
