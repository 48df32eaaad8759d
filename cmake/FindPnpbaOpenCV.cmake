# Finds the OpenCV modules pnpba uses from Debian's per-module packages
# (libopencv-<module>-dev), which ship headers and libraries but no OpenCVConfig.cmake.
# Defines imported targets opencv::<module> for core, imgproc, imgcodecs, features2d, calib3d.
include(FindPackageHandleStandardArgs)

find_path(PnpbaOpenCV_INCLUDE_DIR opencv2/core.hpp PATH_SUFFIXES opencv4)
set(_pnpba_opencv_modules core imgproc imgcodecs features2d calib3d)
set(_pnpba_opencv_required PnpbaOpenCV_INCLUDE_DIR)
foreach(m IN LISTS _pnpba_opencv_modules)
  find_library(PnpbaOpenCV_${m}_LIBRARY NAMES opencv_${m})
  list(APPEND _pnpba_opencv_required PnpbaOpenCV_${m}_LIBRARY)
endforeach()
find_package_handle_standard_args(PnpbaOpenCV REQUIRED_VARS ${_pnpba_opencv_required})

if(PnpbaOpenCV_FOUND)
  foreach(m IN LISTS _pnpba_opencv_modules)
    if(NOT TARGET opencv::${m})
      add_library(opencv::${m} UNKNOWN IMPORTED)
      set_target_properties(opencv::${m} PROPERTIES
        IMPORTED_LOCATION "${PnpbaOpenCV_${m}_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${PnpbaOpenCV_INCLUDE_DIR}")
    endif()
  endforeach()
endif()
