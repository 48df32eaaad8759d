# Type stub of pnpba/__init__.py, whose names load from the extension on first use.
from ._pnpba import BalProblem as BalProblem
from ._pnpba import BalSummary as BalSummary
from ._pnpba import Camera as Camera
from ._pnpba import Error as Error
from ._pnpba import FrameFeatures as FrameFeatures
from ._pnpba import TwoViewResult as TwoViewResult
from ._pnpba import check_two_view_options as check_two_view_options
from ._pnpba import describe_frame as describe_frame
from ._pnpba import estimate_two_view as estimate_two_view
from ._pnpba import evaluate_tum as evaluate_tum
from ._pnpba import preload_depth_registration as preload_depth_registration
from ._pnpba import read_bal as read_bal
from ._pnpba import solve_bal as solve_bal
from ._pnpba import tum_camera as tum_camera
from ._pnpba import tum_camera_for_folder as tum_camera_for_folder
from ._pnpba import tum_frames as tum_frames
from ._pnpba import tum_freiburg1_camera as tum_freiburg1_camera

__all__: list[str]
