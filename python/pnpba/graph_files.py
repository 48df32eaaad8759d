"""The files pnpba-batch writes from a whole results file: a g2o pose graph, a TUM trajectory
chained over consecutive pairs, the chain check and a CSV summary. Kept apart from batch.py so
that the command line starts without NumPy (`pnpba-batch --help`)."""
import csv
import io
import math
import os

import numpy as np

from pnpba.batch import InputError


def _matrix(record):
    return np.array(record["T"], dtype=float)


def _quaternion(R):
    """(x, y, z, w), w >= 0, of a rotation matrix."""
    w = math.sqrt(max(0.0, 1 + R[0, 0] + R[1, 1] + R[2, 2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1 + R[0, 0] - R[1, 1] - R[2, 2])) / 2, R[2, 1] - R[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1 - R[0, 0] + R[1, 1] - R[2, 2])) / 2, R[0, 2] - R[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1 - R[0, 0] - R[1, 1] + R[2, 2])) / 2, R[1, 0] - R[0, 1])
    q = np.array([x, y, z, w])
    return q / np.linalg.norm(q)


# g2o's EDGE_SE3:QUAT error for a measurement Z between vertices i, j (camera-to-world poses):
# delta = Z^-1 (T_wi^-1 T_wj), e = [t(delta); qvec(delta)]. Our covariance C is of d in
# T_21 = exp(d) T_21_est (d = [rotation; translation], left perturbation). With Z = T_12 =
# T_21^-1: delta = exp(-d), so e = -[v; w / 2] to first order: e = -P d, P = [[0, I], [I/2, 0]],
# and g2o's information is (P C P')^-1.
G2O_FROM_TANGENT = np.block([[np.zeros((3, 3)), np.eye(3)], [0.5 * np.eye(3), np.zeros((3, 3))]])


def g2o_information(covariance):
    C = np.asarray(covariance, dtype=float)
    info = np.linalg.inv(G2O_FROM_TANGENT @ C @ G2O_FROM_TANGENT.T)
    return 0.5 * (info + info.T)


def _vertex_ids(pairs):
    ids = {}
    for p in pairs:
        for frame in (p["frame1"], p["frame2"]):
            ids.setdefault(frame, len(ids))
    return ids


def _chain(pairs, records):
    """Camera-to-world poses by walking accepted edges from the first vertex (breadth first)."""
    ids = _vertex_ids(pairs)
    by_id = {r["id"]: r for r in records}
    edges = {}
    for p in pairs:
        r = by_id.get(p["id"])
        if r and r.get("ok") and r.get("T"):
            T12 = np.linalg.inv(_matrix(r))
            edges.setdefault(ids[p["frame1"]], []).append((ids[p["frame2"]], T12))
            edges.setdefault(ids[p["frame2"]], []).append((ids[p["frame1"]], np.linalg.inv(T12)))
    poses = {0: np.eye(4)} if ids else {}
    queue = [0] if ids else []
    while queue:
        i = queue.pop(0)
        for j, T_ij in edges.get(i, []):
            if j not in poses:
                poses[j] = poses[i] @ T_ij
                queue.append(j)
    return ids, poses


def _replace(path, text):
    """Writes text to path via a temporary file and rename (a regular file or a new one), or in
    place for what is not a regular file (a pipe, a device, /dev/stdout)."""
    if os.path.exists(path) and not os.path.isfile(path):
        with open(path, "w") as f:
            f.write(text)
        return
    target = os.path.realpath(path)  # keep a symbolic link a link
    tmp = f"{target}.tmp{os.getpid()}"
    try:
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, target)
    except OSError as e:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise OSError(e.errno, e.strerror, path) from e  # the path the user gave, not tmp's


def write_g2o(path, pairs, records, leave_out=()):
    """VERTEX_SE3:QUAT per frame (chained estimate, identity where unreached), FIX 0, and an
    EDGE_SE3:QUAT per accepted pair with a covariance (but the ids in leave_out): measurement
    T_12 = T_21^-1 (frame 2 in frame 1), information in g2o's order (translation, quaternion
    vector)."""
    records = [r for r in records if r.get("id") not in leave_out]
    ids, poses = _chain(pairs, records)
    by_id = {r["id"]: r for r in records}
    out = io.StringIO()
    for frame, i in ids.items():
        T = poses.get(i, np.eye(4))
        out.write("VERTEX_SE3:QUAT %d %s %s\n" % (i, " ".join("%.9g" % v for v in T[:3, 3]),
                                                   " ".join("%.9g" % v for v in _quaternion(T[:3, :3]))))
    if ids:
        out.write("FIX 0\n")
    edges = 0
    for p in pairs:
        r = by_id.get(p["id"])
        if not (r and r.get("ok") and r.get("covariance")):
            continue
        T12 = np.linalg.inv(_matrix(r))
        info = g2o_information(r["covariance"])
        upper = [info[a, b] for a in range(6) for b in range(a, 6)]
        out.write("EDGE_SE3:QUAT %d %d %s %s %s\n" % (
            ids[p["frame1"]], ids[p["frame2"]], " ".join("%.9g" % v for v in T12[:3, 3]),
            " ".join("%.9g" % v for v in _quaternion(T12[:3, :3])),
            " ".join("%.12g" % v for v in upper)))
        edges += 1
    _replace(path, out.getvalue())
    return edges


def write_trajectory(path, pairs, records):
    """TUM 'stamp tx ty tz qx qy qz qw' lines (camera to world, the first frame at the origin)
    chained over consecutive accepted pairs; stops at the first pair without a pose. Returns
    the number of poses written."""
    by_id = {r["id"]: r for r in records}
    consecutive = sorted((p for p in pairs if p.get("stamp1") is not None and
                          p["frame2"] == p["frame1"] + 1), key=lambda p: p["frame1"])
    if not consecutive:
        raise InputError("--trajectory needs a TUM folder's consecutive pairs")
    T = np.eye(4)
    lines = []

    def line(stamp, T):
        q = _quaternion(T[:3, :3])
        return "%.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f" % (stamp, *T[:3, 3], *q)

    lines.append(line(consecutive[0]["stamp1"], T))
    for p in consecutive:
        r = by_id.get(p["id"])
        if not (r and r.get("ok") and r.get("T")):
            break
        T = T @ np.linalg.inv(_matrix(r))
        lines.append(line(p["stamp2"], T))
    _replace(path, "\n".join(lines) + "\n")
    return len(lines)


def write_chain_check(path, pairs, records):
    """Each accepted pair two or more frames apart whose consecutive pairs all have a pose, its
    chi-squared against their chain (chain_check.py), as TSV 'id frame1 frame2 chi2
    contradicted'. Returns (how many were tested, the contradicted ones' ids)."""
    from pnpba import chain_check

    tested = chain_check.chain_chi2(pairs, records)
    contradicted = [p["id"] for p, chi2 in tested if chi2 > chain_check.CHI2_6DOF_999]
    lines = ["id\tframe1\tframe2\tchi2\tcontradicted"]
    for p, chi2 in tested:
        lines.append("%s\t%d\t%d\t%.6g\t%d" % (p["id"], p["frame1"], p["frame2"], chi2,
                                               chi2 > chain_check.CHI2_6DOF_999))
    _replace(path, "\n".join(lines) + "\n")
    return len(tested), contradicted


def write_csv(path, records):
    out = io.StringIO()
    w = csv.writer(out)
    w.writerow(["id", "ok", "path", "failure_rule", "sigma_deg", "sigma_cm", "total_ms", "error"])
    for r in records:
        w.writerow([r["id"], int(bool(r.get("ok"))), r.get("path", ""), r.get("failure_rule", ""),
                    r.get("sigma_deg", ""), r.get("sigma_cm", ""),
                    r.get("timings_ms", {}).get("total", ""), r.get("error", r.get("failure", ""))])
    _replace(path, out.getvalue())
