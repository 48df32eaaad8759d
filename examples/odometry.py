#!/usr/bin/env python3
"""Visual odometry over a TUM RGB-D folder with pnpba: each consecutive pair's pose, every frame's
features found once (describe_frame) and given to both pairs it is in, the poses chained into a
trajectory (TUM format: stamp tx ty tz qx qy qz qw, camera to world, the first frame at the
origin).

    PYTHONPATH=build/python python3 examples/odometry.py ../shared/data/tum_fr1_desk \
        --trajectory odometry.txt
"""
import argparse
import sys
import time

import cv2
import numpy as np

import pnpba


def read(path, flags):
    image = cv2.imread(path, flags)
    if image is None:
        sys.exit(f"odometry.py: {path}: cannot read the image")
    return image


def quaternion(R):
    """(qx, qy, qz, qw) of a rotation matrix, qw >= 0."""
    w = np.sqrt(max(0.0, 1.0 + R[0, 0] + R[1, 1] + R[2, 2])) / 2
    x = np.sqrt(max(0.0, 1.0 + R[0, 0] - R[1, 1] - R[2, 2])) / 2
    y = np.sqrt(max(0.0, 1.0 - R[0, 0] + R[1, 1] - R[2, 2])) / 2
    z = np.sqrt(max(0.0, 1.0 - R[0, 0] - R[1, 1] + R[2, 2])) / 2
    x = np.copysign(x, R[2, 1] - R[1, 2])
    y = np.copysign(y, R[0, 2] - R[2, 0])
    z = np.copysign(z, R[1, 0] - R[0, 1])
    return x, y, z, w


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="a TUM RGB-D folder (rgb.txt, depth.txt or associate.txt)")
    parser.add_argument("--camera", default="", help="camera YAML (default: the folder's rule)")
    parser.add_argument("--trajectory", help="write the chained poses here (TUM format)")
    args = parser.parse_args()

    try:
        frames = pnpba.tum_frames(args.folder)
        camera = pnpba.tum_camera_for_folder(args.folder, args.camera)["camera"]
    except pnpba.Error as e:
        sys.exit(f"odometry.py: {e}")
    if len(frames) < 2:
        sys.exit(f"odometry.py: {args.folder}: fewer than two frames")

    def load(frame):
        """The frame's images, its features and the milliseconds they took to find."""
        colour = read(frame["rgb"], cv2.IMREAD_COLOR)
        depth = read(frame["depth"], cv2.IMREAD_UNCHANGED)
        start = time.perf_counter()
        features = pnpba.describe_frame(colour)
        return colour, depth, features, 1e3 * (time.perf_counter() - start)

    pose = np.eye(4)  # camera k to world
    poses = [pose]
    previous = load(frames[0])
    times = []
    for k in range(1, len(frames)):
        current = load(frames[k])
        try:
            r = pnpba.estimate_two_view(previous[0], previous[1], current[0], current[1],
                                        camera=camera, features1=previous[2], features2=current[2])
        except pnpba.Error as e:
            sys.exit(f"odometry.py: frame {k}: {e}")
        # A step: the new frame described, and the estimate given both frames' features.
        times.append(current[3] + r.timings_ms["total"])
        if r.ok:
            pose = pose @ np.linalg.inv(r.T)  # X2 = T X1: camera k in camera k-1's frame
            print(f"{k - 1:4d} -> {k:4d}  {r.path:18s} 1-sigma {r.sigma_deg:.2f} deg "
                  f"{r.sigma_cm:.2f} cm  {times[-1]:.1f} ms")
        else:
            print(f"{k - 1:4d} -> {k:4d}  refused: {r.failure} (the pose is held)")
        poses.append(pose)
        previous = current
    print(f"{len(times)} steps, median {np.median(times):.1f} ms a step (the new frame described "
          f"and the estimate)")
    if args.trajectory:
        with open(args.trajectory, "w") as f:
            for frame, T in zip(frames, poses):
                t, q = T[:3, 3], quaternion(T[:3, :3])
                f.write(f"{frame['rgb_stamp']:.6f} " + " ".join(f"{v:.6f}" for v in (*t, *q)) +
                        "\n")
        print(f"trajectory written to {args.trajectory}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
