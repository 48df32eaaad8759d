#!/usr/bin/env python3
"""Relocalisation against one key frame with pnpba: every other frame of a TUM RGB-D folder
estimated from the key frame (image 1), the key frame described once (describe_frame) and given
to every pair, so that what an estimate finds for it later (the SIFT retry's features, its depth's
description for the registration) is found once too.

    PYTHONPATH=build/python python3 examples/relocalise.py \
        ../shared/data/tum_fr3_cabinet_keyframes --key 0 --frames 1-6
"""
import argparse
import sys

import cv2
import numpy as np

import pnpba


def read(path, flags):
    image = cv2.imread(path, flags)
    if image is None:
        sys.exit(f"relocalise.py: {path}: cannot read the image")
    return image


def frame_range(text, count):
    """Frame indices from 'A-B' (inclusive), or every frame for an empty text."""
    if not text:
        return list(range(count))
    try:
        first, last = (int(v) for v in text.split("-"))
    except ValueError:
        sys.exit(f"relocalise.py: --frames {text}: expected FIRST-LAST, e.g. 1-6")
    if first > last:
        sys.exit(f"relocalise.py: --frames {text}: FIRST is past LAST")
    if not 0 <= first <= last < count:
        sys.exit(f"relocalise.py: --frames {text}: the folder has frames 0-{count - 1}")
    return list(range(first, last + 1))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="a TUM RGB-D folder (rgb.txt, depth.txt or associate.txt)")
    parser.add_argument("--key", type=int, default=0, help="the key frame's index (default 0)")
    parser.add_argument("--frames", default="", help="the frames to relocalise, FIRST-LAST "
                        "(default: every frame but the key frame)")
    parser.add_argument("--camera", default="", help="camera YAML (default: the folder's rule)")
    args = parser.parse_args()

    try:
        frames = pnpba.tum_frames(args.folder)
        camera = pnpba.tum_camera_for_folder(args.folder, args.camera)["camera"]
    except pnpba.Error as e:
        sys.exit(f"relocalise.py: {e}")
    if not 0 <= args.key < len(frames):
        sys.exit(f"relocalise.py: --key {args.key}: the folder has frames 0-{len(frames) - 1}")
    key = frames[args.key]
    key_colour = read(key["rgb"], cv2.IMREAD_COLOR)
    key_depth = read(key["depth"], cv2.IMREAD_UNCHANGED)
    key_features = pnpba.describe_frame(key_colour)

    times = []
    for k in frame_range(args.frames, len(frames)):
        if k == args.key:
            continue
        colour = read(frames[k]["rgb"], cv2.IMREAD_COLOR)
        depth = read(frames[k]["depth"], cv2.IMREAD_UNCHANGED)
        try:
            r = pnpba.estimate_two_view(key_colour, key_depth, colour, depth, camera=camera,
                                        features1=key_features)
        except pnpba.Error as e:
            sys.exit(f"relocalise.py: frame {k}: {e}")
        times.append(r.timings_ms["total"])
        if r.ok:
            turn = np.degrees(np.arccos(np.clip((np.trace(r.T[:3, :3]) - 1) / 2, -1, 1)))
            print(f"{args.key:4d} -> {k:4d}  {r.path:18s} {turn:6.1f} deg "
                  f"{100 * np.linalg.norm(r.T[:3, 3]):6.1f} cm  1-sigma {r.sigma_deg:.2f} deg "
                  f"{r.sigma_cm:.2f} cm  {times[-1]:.1f} ms")
        else:
            print(f"{args.key:4d} -> {k:4d}  refused ({r.failure_rule}): {r.failure}  "
                  f"{times[-1]:.1f} ms")
    if not times:
        sys.exit("relocalise.py: no frame to relocalise")
    print(f"{len(times)} frames, median {np.median(times):.1f} ms; the key frame's SIFT feature "
          f"sets kept: {key_features.later_features}, depth descriptions kept: "
          f"{key_features.later_depth_descriptions}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
