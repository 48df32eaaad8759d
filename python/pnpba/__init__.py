"""pnpba: two-view RGB-D camera pose, BAL bundle adjustment and TUM evaluation.

    import cv2, pnpba
    camera = pnpba.Camera.from_yaml("data/images/camera.yaml")
    r = pnpba.estimate_two_view(cv2.imread("1.png"), cv2.imread("1_depth.png", cv2.IMREAD_UNCHANGED),
                                cv2.imread("2.png"), cv2.imread("2_depth.png", cv2.IMREAD_UNCHANGED),
                                camera=camera)
    if r.ok:
        print(r.T, r.sigma_deg, r.sigma_cm)
    else:
        print(r.failure)
"""
from ._pnpba import (  # noqa: F401
    BalProblem,
    BalSummary,
    Camera,
    Error,
    TwoViewResult,
    check_two_view_options,
    estimate_two_view,
    evaluate_tum,
    preload_depth_registration,
    read_bal,
    solve_bal,
    tum_camera,
    tum_camera_for_folder,
    tum_frames,
    tum_freiburg1_camera,
)

__all__ = [
    "BalProblem",
    "BalSummary",
    "Camera",
    "Error",
    "TwoViewResult",
    "check_two_view_options",
    "tum_camera",
    "tum_camera_for_folder",
    "tum_frames",
    "tum_freiburg1_camera",
    "estimate_two_view",
    "evaluate_tum",
    "preload_depth_registration",
    "read_bal",
    "solve_bal",
]
