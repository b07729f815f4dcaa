#!/usr/bin/env python3
"""Simulates a built-in scene, runs the line pipeline on its events and scores the segments against
the scene's exact lines, as `evldt-eval --scene` does.

    evaluate_scene.py [SCENE] [DURATION_S]      (three-lines-fast for 0.5 s by default)"""
import sys

import evldt

scene = sys.argv[1] if len(sys.argv) > 1 else "three-lines-fast"
duration_s = float(sys.argv[2]) if len(sys.argv) > 2 else 0.5
simulation = evldt.simulate(scene, duration_s=duration_s)
pipeline = evldt.Pipeline(simulation.width, simulation.height)
segments = pipeline.process(simulation.events)
result = evldt.evaluate(segments, simulation.ground_truth, simulation.width, simulation.height)
print(f"{scene}: {len(simulation.events)} events, {len(segments)} segment rows")
for row in result["accuracy"]:
    print(f"  at {row['tolerance'] * 100:g}% of the diagonal: P {row['precision']:.3f}  R {row['recall']:.3f}  F {row['f']:.3f}")
