// The TUM RGB-D benchmark's three cameras (its published calibration) and which one a sequence
// folder was recorded with. evaluate_tum and pnpba-batch take a folder's camera from, in order:
// --camera FILE, FOLDER/camera.yaml, the freiburg camera the folder's path names
// ("rgbd_dataset_freiburg3_cabinet", "tum_fr3_cabinet_keyframes"), else freiburg1 with a note.
// A wrong guess costs accuracy quietly (the shared fr3_cabinet key frames through freiburg1's
// intrinsics and distortion: 27/54 pairs within 1 deg / 2 cm and 2 failed, against 32/54 and
// none), so the choice is always reported.
#pragma once

#include <string>

#include "pnpba/pipeline/camera.h"

namespace pnpba {

// Freiburg 1 (Kinect), 2 (Kinect) or 3 (Asus Xtion, colour images already undistorted by the
// benchmark); depth in 1/5000 m. Throws Error for another number.
Camera tumFreiburgCamera(int freiburg);
Camera tumFreiburg1Camera();

// 1, 2 or 3 when the folder's path names that freiburg camera ("freiburgN" or "frN" as a word of
// a path component, the innermost component that names one deciding); 0 when none does, or when
// that component names two.
int tumFreiburgNamedBy(const std::string& folder);

struct SequenceCamera {
  Camera camera;
  // Where it came from, for a user to read: the YAML's path, "TUM freiburg3 (named by the
  // folder)" or "TUM freiburg1 (assumed: ...)".
  std::string source;
  int freiburg = 0;      // the TUM camera taken (1, 2, 3), 0 for a YAML
  bool assumed = false;  // freiburg1 by default: nothing named the camera
};

// The camera of a TUM folder by the rules above; `camera_path` empty for none given. Throws
// Error for a YAML that cannot be read.
SequenceCamera sequenceCamera(const std::string& folder, const std::string& camera_path);

}  // namespace pnpba
