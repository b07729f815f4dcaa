#!/usr/bin/env python3
"""Speed of evldt.Pipeline.process against evldt-offline on the same recording: evldt-sim writes
the scene as EVT 3.0, evldt-offline runs it (its summary's events / wall time: decoding, validation,
filters, pipeline and CSV), and Pipeline.process runs the events evldt.read got from the same file
(validation, filters and pipeline). Medians of --repeats runs each, alternating.

    /usr/bin/python3 tools/python-bench.py [--build build/release] [--scene three-lines-fast] [--repeats 5]
"""
import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--build", default="build/release", help="build folder (default: build/release)")
parser.add_argument("--scene", default="three-lines-fast")
parser.add_argument("--repeats", type=int, default=5)
args = parser.parse_args()
build = pathlib.Path(args.build).resolve()
sys.path.insert(0, str(build / "python"))
import evldt  # noqa: E402  (from the build folder)

with tempfile.TemporaryDirectory() as folder:
    folder = pathlib.Path(folder)
    subprocess.run([build / "tools/evldt-sim/evldt-sim", "--scene", args.scene, "--out-dir", folder, "--format", "evt3",
                    "--quiet"], check=True, capture_output=True)
    path = folder / "events.raw"
    recording = evldt.read(path)
    events = recording.events
    offline_rates, python_rates = [], []
    for _ in range(args.repeats):
        subprocess.run([build / "tools/evldt-offline/evldt-offline", path, "-o", folder / "s.csv", "-q",
                        "--summary-json", folder / "s.json"], check=True, capture_output=True)
        summary = json.loads((folder / "s.json").read_text())
        offline_rates.append(summary["events_read"] / summary["wall_seconds"] / 1e6)
        pipeline = evldt.Pipeline(recording.width, recording.height)
        started = time.perf_counter()
        pipeline.process(events)
        python_rates.append(len(events) / (time.perf_counter() - started) / 1e6)
    offline, python = statistics.median(offline_rates), statistics.median(python_rates)
    print(f"{args.scene}: {len(events)} events, {recording.width}x{recording.height}, medians of {args.repeats}")
    print(f"  evldt-offline           {offline:6.2f} Mev/s  (runs {min(offline_rates):.2f}-{max(offline_rates):.2f})")
    print(f"  evldt.Pipeline.process  {python:6.2f} Mev/s  (runs {min(python_rates):.2f}-{max(python_rates):.2f})")
    print(f"  Python / C++            {python / offline:6.2f}")
