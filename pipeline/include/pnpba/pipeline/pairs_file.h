// Reads 3D-2D pair files: one pair per line, "X Y Z u2 v2 [u1 v1]" (camera-1 metres, image-2
// pixels, optional image-1 pixels); '#' starts a comment. The format of
// shared/data/reference/ch7_pairs_75.txt and of --pairs in the apps.
#pragma once

#include <string>
#include <vector>

#include "pnpba/pipeline/pose_graph.h"

namespace pnpba {

struct PairsFile {
  std::vector<PointPair> pairs;
  bool has_image1_pixels = false;  // every line had u1 v1
};

// Throws Error "<path>:<line>: <problem>" on a malformed line, non-finite number, depth <= 0,
// a mix of 5- and 7-column lines, or a file with no pairs.
PairsFile readPairsFile(const std::string& path);

}  // namespace pnpba
