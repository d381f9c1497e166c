#!/usr/bin/env python3
"""Per-frame overhead of the Python binding: wall time of `LaneTracker.track` seen from Python minus
the Rust tracker's own time on the same call (`last_track_us`), median over a clip, 3 passes.

    cargo xtask python            # builds the release wheel into target/py-venv
    target/py-venv/bin/python bench/python_overhead.py [CLIP.y4m]
"""
import os
import statistics
import sys
import time

import numpy as np

import ita_nav

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
clip = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
    ROOT, "..", "shared", "data", "udacity", "solidWhiteRight-320x240-gray.y4m")
frames = ita_nav.read_frames(clip)
overhead, total, rust = [], [], []
for kind, convert in (("grey", lambda f: f), ("rgb", lambda f: np.repeat(f[:, :, None], 3, axis=2))):
    inputs = [convert(f) for f in frames]
    overhead, total, rust = [], [], []
    for _ in range(3):
        t = ita_nav.LaneTracker()
        for f in inputs:
            t0 = time.perf_counter()
            t.track(f)
            dt = 1e6 * (time.perf_counter() - t0)
            total.append(dt)
            rust.append(t.last_track_us)
            overhead.append(dt - t.last_track_us)
    print(f"{kind:4s} {frames[0].shape[1]}x{frames[0].shape[0]}, {len(frames)} frames x 3: "
          f"track() median {statistics.median(total):6.1f} us, Rust tracker {statistics.median(rust):6.1f} us, "
          f"binding overhead median {statistics.median(overhead):5.2f} us (p90 {statistics.quantiles(overhead, n=10)[-1]:5.2f} us)")
