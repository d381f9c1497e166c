#!/usr/bin/env python3
"""The tracker's own time per frame from `nav-app --json` (`track_us`, docs/json.md): median, mean,
their ratio, 90th percentile and largest, over every frame of the run; and on how many frames both
lanes were tracking. The summary line (no `track_us`) is skipped.

    cargo build --release -p nav-app --no-default-features
    target/release/nav-app --input ../shared/data/udacity/solidWhiteRight-320x240-gray.y4m --json \\
        | python3 bench/track_us_stats.py

Wall times on a shared machine: run it a few times (docs/results/speed.md, "The whole real clip").
"""
import json
import statistics
import sys

times_us = []
both = 0
for line in sys.stdin:
    frame = json.loads(line)
    if "track_us" not in frame:
        continue
    times_us.append(frame["track_us"])
    both += all(lane["state"] == "tracking" for lane in frame["lanes"])
if not times_us:
    sys.exit("no frame with track_us on stdin (nav-app --json)")
median = statistics.median(times_us)
mean = statistics.mean(times_us)
ordered = sorted(times_us)
p90 = ordered[min(len(ordered) - 1, int(0.9 * len(ordered)))]
print(
    f"{len(times_us)} frames, both lanes tracking on {both}; track_us: median {median:.1f} µs, "
    f"mean {mean:.1f} µs (mean/median {mean / median:.2f}), 90th percentile {p90:.1f} µs, "
    f"largest {ordered[-1]:.1f} µs"
)
