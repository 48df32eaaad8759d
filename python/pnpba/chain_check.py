"""pnpba.chain_check: each pose of a pair two or more frames apart, tested against the poses of
the consecutive pairs between its frames, chained.

A wrong pose can be consistent with everything in its own pair: around a free-standing symmetric
object the depth path can return the scene's half turn (docs/two_view.md, "Which loops catch
it"), and two such poses close a triangle with a right one, so triangles of pairs do not show it.
The chain of consecutive pairs does. The test is a chi-squared test of the difference under the
two estimates' covariances: pnpba's covariance C is of d in T_21 = exp(d) T_21_est (d =
[rotation; translation], a left perturbation), and chaining T_c = T_k ... T_1 gives
C_c = C_k + Ad(T_k) C_(k-1..1) Ad(T_k)', Ad(T) = [[R, 0], [t^ R, R]]. The difference
D = T_21 T_c^-1 = exp(d) exp(-Ad(D) d_c) D_est has covariance C + Ad(D) C_c Ad(D)', and a pose
is contradicted where log(D)' (C + Ad C_c Ad')^-1 log(D) exceeds chi-squared's 99.9 % point for
six degrees of freedom.
"""
import math

import numpy as np

CHI2_6DOF_999 = 22.457744484825326  # chi-squared with 6 degrees of freedom, 99.9 % quantile


def _hat(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def adjoint(T):
    """Ad(T) for [rotation; translation] tangents: exp(d) T = T exp(Ad(T)^-1 d)."""
    R, t = T[:3, :3], T[:3, 3]
    A = np.zeros((6, 6))
    A[:3, :3] = R
    A[3:, 3:] = R
    A[3:, :3] = _hat(t) @ R
    return A


def log_se3(T):
    """[w; v] with exp([w; v]) = T (the inverse of SE(3)'s exp, as pnpba's SE3Quat::log)."""
    R = T[:3, :3]
    cos = min(1.0, max(-1.0, (np.trace(R) - 1.0) / 2.0))
    theta = math.acos(cos)
    if theta < 1e-9:
        w = np.zeros(3)
    elif theta > math.pi - 1e-6:
        # Near a half turn the axis is the column of (R + I) / 2 with the largest diagonal.
        M = (R + np.eye(3)) / 2.0
        k = int(np.argmax(np.diag(M)))
        w = theta * M[:, k] / math.sqrt(M[k, k])
    else:
        w = theta / (2.0 * math.sin(theta)) * np.array(
            [R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    theta = float(np.linalg.norm(w))
    W = _hat(w)
    if theta < 1e-9:
        V_inv = np.eye(3) - 0.5 * W
    else:
        V_inv = (np.eye(3) - 0.5 * W + (1.0 - theta * math.sin(theta) /
                                        (2.0 * (1.0 - math.cos(theta)))) / theta**2 * W @ W)
    return np.concatenate([w, V_inv @ T[:3, 3]])


def _pose(record):
    """The record's (T_21, covariance), or None when it has no pose with a covariance."""
    if not (record and record.get("ok") and record.get("T") and record.get("covariance")):
        return None
    return np.array(record["T"], dtype=float), np.array(record["covariance"], dtype=float)


def chain_chi2(pairs, records):
    """For every accepted pair (i, j) of a TUM folder's frames with j >= i + 2 whose consecutive
    pairs (i, i+1) ... (j-1, j) all have a pose: (pair, chi2 of its pose against their chain).
    Pairs without frame numbers, or without a complete chain, are left out."""
    by_id = {r["id"]: r for r in records if "id" in r}
    consecutive = {}
    for p in pairs:
        if p.get("frame1") is not None and p.get("frame2") == p["frame1"] + 1:
            pose = _pose(by_id.get(p["id"]))
            if pose is not None:
                consecutive[p["frame1"]] = pose
    # The pairs to test by first frame; each first frame's chain is extended one consecutive pose
    # at a time, serving every pair that starts there (not rebuilt per pair).
    tested_from = {}
    for p in pairs:
        i, j = p.get("frame1"), p.get("frame2")
        if i is not None and j is not None and j >= i + 2:
            pose = _pose(by_id.get(p["id"]))
            if pose is not None:
                tested_from.setdefault(i, {})[j] = (p, pose)
    out = []
    for i, by_last in tested_from.items():
        T_chain, C_chain = np.eye(4), np.zeros((6, 6))
        for k in range(i, max(by_last)):
            if k not in consecutive:
                break
            T_k, C_k = consecutive[k]
            A = adjoint(T_k)
            C_chain = C_k + A @ C_chain @ A.T
            T_chain = T_k @ T_chain
            if k + 1 not in by_last:
                continue
            p, (T, C) = by_last[k + 1]
            D = T @ np.linalg.inv(T_chain)
            A = adjoint(D)
            e = log_se3(D)
            S = C + A @ C_chain @ A.T
            try:
                out.append((p, float(e @ np.linalg.solve(S, e))))
            except np.linalg.LinAlgError:  # a singular covariance tests nothing
                continue
    return out
