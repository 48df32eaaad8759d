# SE(3) maths the Python tests compute independently of the module under test.
import math

import numpy as np


def se3_exp(d):
    """exp of [w; v] as a 4x4 matrix (Rodrigues and the SE(3) V matrix)."""
    w, v = np.asarray(d[:3], float), np.asarray(d[3:], float)
    th = np.linalg.norm(w)
    K = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    if th < 1e-12:
        R, V = np.eye(3) + K, np.eye(3) + K / 2
    else:
        R = np.eye(3) + math.sin(th) / th * K + (1 - math.cos(th)) / th**2 * K @ K
        V = np.eye(3) + (1 - math.cos(th)) / th**2 * K + (th - math.sin(th)) / th**3 * K @ K
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, V @ v
    return T
