// The textbook pair's reference data (shared/data/reference): the 75 pairs as the reference
// tools saw them, and the reference poses T_21 of its README. Shared by tests and benchmarks.
#pragma once

#include <string>
#include <vector>

#include "pnpba/optimize/se3_quat.h"
#include "pnpba/pipeline/pairs_file.h"

namespace pnpba::test {

inline SE3Quat poseFromRowMajor(const double (&r)[9], const double (&t)[3]) {
  Eigen::Matrix3d R;
  R << r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8];
  return SE3Quat(R, Eigen::Vector3d(t[0], t[1], t[2]));
}

// OpenCV SOLVEPNP_EPNP on the 75 pairs.
inline SE3Quat referenceEpnpPose() {
  return poseFromRowMajor({0.9978745555297592, -0.05102729297915264, 0.04052883908410343,
                           0.04983267620066807, 0.9983081506312504, 0.02995898472732319,
                           -0.04198899628432191, -0.02787564805403336, 0.9987291286613217},
                          {-0.1273034869580338, -0.01157187487421864, 0.05667408337434066});
}
// Least squares (OpenCV SOLVEPNP_ITERATIVE = g2o pose-only LM).
inline SE3Quat referenceLeastSquaresPose() {
  return poseFromRowMajor({0.9979059095501264, -0.05091940089110115, 0.03988747043654633,
                           0.0498186625425323, 0.998362315743816, 0.02812094175376019,
                           -0.04125404886078842, -0.02607491352883862, 0.9988083912027648},
                          {-0.1267821389558076, -0.008439496817513407, 0.06034935748888434});
}
// g2o, textbook graph.
inline SE3Quat referenceG2oTextbookPose() {
  return poseFromRowMajor({0.99784828967049299, -0.051087888004137667, 0.041095236961824641,
                           0.049905939585145921, 0.99832431076966899, 0.029291086022697914,
                           -0.042522793838076958, -0.027177163677286321, 0.99872579509025516},
                          {-0.12845421135044624, -0.01032761175644482, 0.059049411959560406});
}
// g2o, textbook graph + fixed identity camera 1.
inline SE3Quat referenceG2oTwoCameraPose() {
  return poseFromRowMajor({0.99711756939602769, -0.050402588359046124, 0.056710950340003959,
                           0.048467726359245775, 0.99821162156880971, 0.034991971458215809,
                           -0.058373215632883536, -0.032142458706139229, 0.99777724470194296},
                          {-0.15653804047033512, -0.020070985574176581, 0.045196057709136844});
}

// The reference was computed from float (cv::Point3f / Point2f) values; the file's decimals
// read back as float give them exactly.
inline std::vector<PointPair> referencePairs(const std::string& shared_data) {
  auto to_float = [](auto v) { return v.template cast<float>().template cast<double>().eval(); };
  std::vector<PointPair> pairs = readPairsFile(shared_data + "/reference/ch7_pairs_75.txt").pairs;
  for (PointPair& p : pairs) {
    p.X_1 = to_float(p.X_1);
    p.uv_1 = to_float(p.uv_1);
    p.uv_2 = to_float(p.uv_2);
  }
  return pairs;
}

}  // namespace pnpba::test
