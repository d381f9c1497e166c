"""Track the real udacity highway frames (from the data root, ../shared/data) and print both lanes' bottom-row columns.

    python crates/ita-nav-py/examples/track_clip.py [CLIP.y4m]
"""
import sys

import ita_nav

clip = sys.argv[1] if len(sys.argv) > 1 else "../shared/data/udacity/solidWhiteRight-320x240-gray.y4m"
tracker = ita_nav.LaneTracker()  # default configuration
for i, frame in enumerate(ita_nav.read_frames(clip)):
    left, right = tracker.track(frame)
    y = frame.shape[0] - 1
    cols = [None if l["coeffs"] is None else round((l["coeffs"][0] * y + l["coeffs"][1]) * y + l["coeffs"][2], 1) for l in (left, right)]
    print(f"frame {i:3d}: left {left['state']:9s} x={cols[0]}  right {right['state']:9s} x={cols[1]}")
