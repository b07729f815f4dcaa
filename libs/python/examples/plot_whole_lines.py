#!/usr/bin/env python3
"""Simulates a built-in scene, runs the line pipeline with whole lines on its events and draws the
whole lines of the last output step over its block segments (matplotlib, if installed, to a PNG);
without matplotlib it prints them.

    plot_whole_lines.py [SCENE] [DURATION_S] [OUT.png]      (boxes-6dof for 1 s, whole_lines.png)"""
import sys

import evldt

scene = sys.argv[1] if len(sys.argv) > 1 else "boxes-6dof"
duration_s = float(sys.argv[2]) if len(sys.argv) > 2 else 1.0
out = sys.argv[3] if len(sys.argv) > 3 else "whole_lines.png"

simulation = evldt.simulate(scene, duration_s=duration_s)
pipeline = evldt.Pipeline(simulation.width, simulation.height, whole_lines=True)
segments = pipeline.process(simulation.events)
whole = pipeline.whole_lines()
last = whole["t"].max()
segments, whole = segments[segments["t"] == last], whole[whole["t"] == last]
print(f"{scene} at t = {last} us: {len(whole)} whole lines joining {int(whole['score'].sum())} of {len(segments)} segments")

try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: the whole lines as rows (id, x0, y0, x1, y1, segments joined)")
    for line in whole:
        print(f"  {line['id']:6d}  ({line['x0']:7.2f}, {line['y0']:7.2f}) - ({line['x1']:7.2f}, {line['y1']:7.2f})  {int(line['score'])}")
    sys.exit(0)

figure, axes = plt.subplots(figsize=(8, 8 * simulation.height / simulation.width))
for rows, colour, width in ((segments, "tab:red", 1.0), (whole, "tab:blue", 2.5)):
    for line in rows:
        axes.plot([line["x0"], line["x1"]], [line["y0"], line["y1"]], color=colour, linewidth=width)
for line in whole:
    axes.annotate(str(line["id"]), ((line["x0"] + line["x1"]) / 2, (line["y0"] + line["y1"]) / 2), color="tab:blue")
axes.set_xlim(0, simulation.width)
axes.set_ylim(simulation.height, 0)  # image rows grow downwards
axes.set_aspect("equal")
axes.set_title(f"{scene}: whole lines (blue, with ids) over block segments (red)")
figure.savefig(out, dpi=100)
print(f"wrote {out}")
