#!/usr/bin/env python3
"""Side-by-side speed of the classic OpenCV lane pipeline and nav-app, one thread, same frames.

Peer pipeline (what a practitioner would write): grey -> GaussianBlur 5x5 -> Canny(50, 150) ->
region-of-interest mask (rows below 62 % of the height, as nav-app's outdoor preset) ->
HoughLinesP(1 px, 1 deg, 20 votes, min length 20, max gap 10) -> split by slope sign ->
numpy.polyfit(y, x, 2) per side. Per-frame wall time, median over all frames.

nav-app: `nav-app --input CLIP --json` reports `track_us` (wall time of LaneTracker::track) per
frame; median over the same frames.

Setup (once):  python3 -m venv target/opencv-venv && target/opencv-venv/bin/pip install "opencv-python-headless<5"
Run:           cargo build --release -p nav-app --no-default-features && target/opencv-venv/bin/python bench/opencv_peer.py [CLIP.y4m]

Accuracy mode (`cargo xtask eval-lanes` runs it, in the venv it makes on first use):
               bench/opencv_peer.py --predict-set ../shared/data/lanes/SET --out PRED.json
writes, for every frame of the labelled set in order, the peer's ego lanes as
`{"frames": [{"index": i, "lanes": [[a1, a2, a3] | null, [a1, a2, a3] | null]}]}` (left, right;
x = a1*y^2 + a2*y + a3 in the frame's pixels), which the xtask scores with the same rules as nav-app.
"""
import json
import os
import statistics
import subprocess
import sys
import time

import cv2
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_CLIP = os.path.join(ROOT, "..", "shared", "data", "udacity", "solidWhiteRight-320x240-gray.y4m")


def read_y4m_mono(path):
    with open(path, "rb") as f:
        data = f.read()
    header_end = data.index(b"\n")
    tags = dict((t[:1].decode(), t[1:].decode()) for t in data[:header_end].split()[1:])
    w, h = int(tags["W"]), int(tags["H"])
    chroma = tags.get("C", "420jpeg")
    frame_bytes = w * h if chroma.startswith("mono") else w * h + 2 * ((w + 1) // 2) * ((h + 1) // 2)
    frames, pos = [], header_end + 1
    while pos < len(data):
        nl = data.index(b"\n", pos)
        start = nl + 1
        if start + frame_bytes > len(data):
            break
        frames.append(np.frombuffer(data, np.uint8, w * h, start).reshape(h, w).copy())
        pos = start + frame_bytes
    return frames


def opencv_pipeline(grey, roi_mask):
    blur = cv2.GaussianBlur(grey, (5, 5), 0)
    edges = cv2.Canny(blur, 50, 150)
    edges = cv2.bitwise_and(edges, roi_mask)
    lines = cv2.HoughLinesP(edges, 1, np.pi / 180, 20, minLineLength=20, maxLineGap=10)
    fits = []
    if lines is not None:
        seg = np.asarray(lines).reshape(-1, 4).astype(np.float64)  # (N, 1, 4) or (N, 4) by version
        dx = seg[:, 2] - seg[:, 0]
        dy = seg[:, 3] - seg[:, 1]
        slope = np.divide(dy, dx, out=np.zeros_like(dy), where=dx != 0)
        for side in (slope < -0.3, slope > 0.3):
            s = seg[side]
            if len(s) >= 2:
                ys = np.concatenate([s[:, 1], s[:, 3]])
                xs = np.concatenate([s[:, 0], s[:, 2]])
                fits.append(np.polyfit(ys, xs, 2))
    return fits


def opencv_sides(grey, roi_mask):
    """The pipeline above, keeping which side each fit is: [left, right], None where absent."""
    blur = cv2.GaussianBlur(grey, (5, 5), 0)
    edges = cv2.bitwise_and(cv2.Canny(blur, 50, 150), roi_mask)
    lines = cv2.HoughLinesP(edges, 1, np.pi / 180, 20, minLineLength=20, maxLineGap=10)
    out = [None, None]
    if lines is not None:
        seg = np.asarray(lines).reshape(-1, 4).astype(np.float64)  # (N, 1, 4) or (N, 4) by version
        dx = seg[:, 2] - seg[:, 0]
        dy = seg[:, 3] - seg[:, 1]
        slope = np.divide(dy, dx, out=np.zeros_like(dy), where=dx != 0)
        for k, side in enumerate((slope < -0.3, slope > 0.3)):
            s = seg[side]
            if len(s) >= 2:
                ys = np.concatenate([s[:, 1], s[:, 3]])
                xs = np.concatenate([s[:, 0], s[:, 2]])
                out[k] = [float(c) for c in np.polyfit(ys, xs, 2)]
    return out


def predict_set(set_dir, out_path):
    with open(os.path.join(set_dir, "labels.json")) as f:
        labels = json.load(f)
    h, w = labels["height"], labels["width"]
    roi = np.zeros((h, w), np.uint8)
    roi[int(0.62 * h):, :] = 255
    frames = []
    for fr in labels["frames"]:
        grey = cv2.imread(os.path.join(set_dir, fr["file"]), cv2.IMREAD_GRAYSCALE)
        if grey is None or grey.shape != (h, w):
            raise SystemExit(f"{fr['file']}: cannot read a {w}x{h} grey image")
        frames.append({"index": fr["index"], "lanes": opencv_sides(grey, roi)})
    with open(out_path, "w") as f:
        json.dump({"frames": frames}, f)


def main():
    if len(sys.argv) >= 2 and sys.argv[1] == "--predict-set":
        if len(sys.argv) != 5 or sys.argv[3] != "--out":
            raise SystemExit("usage: opencv_peer.py --predict-set SET_DIR --out PRED.json")
        cv2.setNumThreads(1)
        predict_set(sys.argv[2], sys.argv[4])
        return
    clip = sys.argv[1] if len(sys.argv) > 1 else DEFAULT_CLIP
    cv2.setNumThreads(1)
    frames = read_y4m_mono(clip)
    h, w = frames[0].shape
    roi = np.zeros((h, w), np.uint8)
    roi[int(0.62 * h):, :] = 255
    for f in frames[:5]:  # warm-up
        opencv_pipeline(f, roi)
    times = []
    for _ in range(3):
        for f in frames:
            t0 = time.perf_counter()
            opencv_pipeline(f, roi)
            times.append(time.perf_counter() - t0)
    peer_us = 1e6 * statistics.median(times)

    exe = os.path.join(ROOT, "target", "release", "nav-app")
    ours = []
    for _ in range(3):
        out = subprocess.run([exe, "--input", clip, "--json"], check=True, capture_output=True, text=True).stdout
        rows = [json.loads(line) for line in out.splitlines()]
        ours += [r["track_us"] for r in rows if "track_us" in r]  # the last line is the summary
    ours_us = statistics.median(ours)
    print(f"clip: {clip} ({len(frames)} frames, {w}x{h})")
    print(f"opencv {cv2.__version__} classic pipeline (1 thread): median {peer_us:8.1f} us/frame")
    print(f"nav-app LaneTracker::track (KIF, 1 thread):        median {ours_us:8.1f} us/frame")
    print(f"ratio opencv / nav-app: {peer_us / ours_us:.1f}x")


if __name__ == "__main__":
    main()
