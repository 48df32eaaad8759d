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
# The names below come from the compiled extension (_pnpba), which is loaded on first use rather
# than at `import pnpba` (PEP 562): it maps OpenCV, Ceres and the rest, about 10 ms, which a tool
# that only parses its arguments (`pnpba-batch --help`) need not pay. __init__.pyi gives type
# checkers the same names.
__all__ = [
    "BalProblem",
    "BalSummary",
    "Camera",
    "Error",
    "FrameFeatures",
    "TwoViewResult",
    "check_two_view_options",
    "describe_frame",
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


def __getattr__(name):
    if name in __all__:
        from . import _pnpba

        value = getattr(_pnpba, name)
        globals()[name] = value  # found directly from now on
        return value
    raise AttributeError(f"module 'pnpba' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
