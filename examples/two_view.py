#!/usr/bin/env python3
"""Two-view RGB-D pose with pnpba from Python: load with OpenCV, estimate, print T and its
1-sigma, and draw the matches (inliers green, outliers red).

    PYTHONPATH=build/python python3 examples/two_view.py \
        data/images/1.png data/images/2.png data/images/1_depth.png data/images/2_depth.png \
        --camera data/images/camera.yaml --matches matches.png
"""
import argparse
import sys

import cv2
import numpy as np

import pnpba


def read(path, flags):
    image = cv2.imread(path, flags)
    if image is None:
        sys.exit(f"two_view.py: {path}: cannot read the image")
    return image


def draw_matches(r, image1, image2):
    """Both images side by side, a line per 3D-2D pair."""
    canvas = np.hstack([image1, image2])
    offset = image1.shape[1]
    for (k1, k2), inlier in zip(r.matches, r.inlier_mask):
        p1 = tuple(int(round(c)) for c in r.keypoints1[k1])
        x2, y2 = r.keypoints2[k2]
        p2 = (int(round(x2)) + offset, int(round(y2)))
        cv2.line(canvas, p1, p2, (0, 200, 0) if inlier else (0, 0, 255), 1, cv2.LINE_AA)
    return canvas


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("image1")
    parser.add_argument("image2")
    parser.add_argument("depth1")
    parser.add_argument("depth2", nargs="?")
    parser.add_argument("--camera", required=True, help="ORB-SLAM2-style camera YAML")
    parser.add_argument("--matches", help="write the matches drawing to this PNG")
    args = parser.parse_args()

    camera = pnpba.Camera.from_yaml(args.camera)
    image1, image2 = read(args.image1, cv2.IMREAD_COLOR), read(args.image2, cv2.IMREAD_COLOR)
    depth1 = read(args.depth1, cv2.IMREAD_UNCHANGED)
    depth2 = read(args.depth2, cv2.IMREAD_UNCHANGED) if args.depth2 else None
    try:
        r = pnpba.estimate_two_view(image1, depth1, image2, depth2, camera=camera)
    except pnpba.Error as e:
        sys.exit(f"two_view.py: {e}")

    print(f"{r.counts['matches']} matches, {r.counts['pairs']} 3D-2D pairs, {r.inliers} inliers")
    if not r.ok:
        print(f"no pose: {r.failure} (rule: {r.failure_rule or 'none'})")
    else:
        np.set_printoptions(precision=6, suppress=True)
        print(f"T (camera 2 from camera 1, path: {r.path}):\n{r.T}")
        print(f"1-sigma: {r.sigma_deg:.3f} deg, {r.sigma_cm:.2f} cm")
        print(f"time: {r.timings_ms['total']:.1f} ms")
    if args.matches:
        cv2.imwrite(args.matches, draw_matches(r, image1, image2))
        print(f"matches drawn to {args.matches}")
    return 0 if r.ok else 1


if __name__ == "__main__":
    sys.exit(main())
