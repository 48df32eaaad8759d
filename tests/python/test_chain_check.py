# pnpba.chain_check: poses of pairs far apart tested against the chained consecutive pairs, on
# orbits drawn with exact truth and noise drawn from the covariances the records state.
import math

import numpy as np

from pnpba import chain_check
from se3 import se3_exp


def test_log_inverts_exp_also_near_a_half_turn():
    rng = np.random.default_rng(1)
    for angle in (0.0, 1e-5, 0.3, 2.0, math.pi - 1e-3, math.pi - 1e-8):
        axis = rng.normal(size=3)
        d = np.concatenate([angle * axis / np.linalg.norm(axis), rng.normal(size=3)])
        np.testing.assert_allclose(chain_check.log_se3(se3_exp(d)), d, atol=2e-6)


def test_the_adjoint_moves_a_perturbation_across_a_pose():
    rng = np.random.default_rng(2)
    T = se3_exp(rng.normal(size=6))
    d = 1e-3 * rng.normal(size=6)
    # exp(d) T = T exp(Ad(T)^-1 d), against matrices multiplied out.
    right = T @ se3_exp(np.linalg.solve(chain_check.adjoint(T), d))
    np.testing.assert_allclose(se3_exp(d) @ T, right, atol=1e-12)


def orbit(frames, step_deg, radius=2.0):
    """Camera-to-world poses of a camera circling the origin at `radius`, looking at it."""
    poses = []
    for k in range(frames):
        a = math.radians(step_deg * k)
        centre = np.array([radius * math.sin(a), 0.0, -radius * math.cos(a)])
        z = -centre / np.linalg.norm(centre)  # optical axis toward the origin
        y = np.array([0.0, 1.0, 0.0])
        x = np.cross(y, z)
        P = np.eye(4)
        P[:3, :3] = np.column_stack([x, y, z])
        P[:3, 3] = centre
        poses.append(P)
    return poses


def records_of(poses, max_gap, rng, cov, wrong=()):
    """TUM-like pairs (i, j), 1 <= j - i <= max_gap, each with T_21 = exp(d) T_true, d drawn from
    cov; the pairs in `wrong` get the scene's half turn about the vertical through the origin."""
    half_turn = np.diag([-1.0, 1.0, -1.0, 1.0])  # world rotated by pi about y (the orbit's axis)
    pairs, records = [], []
    for i in range(len(poses)):
        for j in range(i + 1, min(i + max_gap, len(poses) - 1) + 1):
            world_j = half_turn @ poses[j] if (i, j) in wrong else poses[j]
            noise = se3_exp(rng.multivariate_normal(np.zeros(6), cov))
            T = noise @ np.linalg.inv(world_j) @ poses[i]
            pid = f"{i}-{j}"
            pairs.append({"id": pid, "frame1": i, "frame2": j, "stamp1": float(i),
                          "stamp2": float(j)})
            records.append({"id": pid, "ok": True, "T": T.tolist(), "covariance": cov.tolist()})
    return pairs, records


def test_the_half_turn_is_contradicted_and_right_poses_read_chi_squared():
    rng = np.random.default_rng(8)
    # 0.5 degrees at 2 m moves a camera 1.7 cm, against 2 mm of translation noise: the chain's
    # covariance is mostly the rotations' carried through the adjoint.
    cov = np.diag([math.radians(0.5) ** 2] * 3 + [0.002**2] * 3)
    poses = orbit(12, 20.0)
    pairs, records = records_of(poses, 8, rng, cov, wrong={(1, 9)})  # 160 degrees round
    tested = chain_check.chain_chi2(pairs, records)
    chi2 = {p["id"]: value for p, value in tested}
    assert len(chi2) == sum(1 for p in pairs if p["frame2"] - p["frame1"] >= 2)
    assert chi2["1-9"] > 100 * chain_check.CHI2_6DOF_999
    right = [value for pid, value in chi2.items() if pid != "1-9"]
    assert max(right) < chain_check.CHI2_6DOF_999
    # Under the stated covariances and their propagation along the chain, a right pose's chi2 is
    # chi-squared with 6 degrees of freedom, mean 6 (these 48 share their chains: their mean read
    # 5.2-8.5 over four seeds; a chain summing covariances without the adjoint read 57-104).
    assert 3 < np.mean(right) < 10, np.mean(right)


def test_a_pose_without_its_whole_chain_or_frame_numbers_is_not_tested():
    rng = np.random.default_rng(3)
    cov = np.diag([1e-4] * 3 + [1e-4] * 3)
    pairs, records = records_of(orbit(5, 10.0), 3, rng, cov)
    for r in records:
        if r["id"] == "1-2":
            r["ok"], r["T"], r["covariance"] = False, None, None
    tested = {p["id"] for p, _ in chain_check.chain_chi2(pairs, records)}
    # (0, 2), (0, 3), (1, 3), (1, 4) chain through (1, 2); (2, 4) does not.
    assert tested == {"2-4"}
    table = [{"id": p["id"]} for p in pairs]  # a pair table's rows have no frame numbers
    assert chain_check.chain_chi2(table, records) == []
