// A bench's output files, by the rule every tool of the project keeps (DESIGN.md section 5,
// core/output_file.h): every path checked before the work starts, so that a bad one costs no
// run of several minutes; every file written whole or not at all (an existing file is replaced
// only once its successor is complete), through a symbolic link or straight into a device or
// pipe. A failure throws pnpba::Error "<path>: <reason>", which guardedMain (guarded_main.h)
// prints as one line with the bench's name, exit 2.
#pragma once

#include <initializer_list>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"
#include "pnpba/imageio/image_codec.h"

namespace pnpba::bench {

// Throws for the first path that cannot be written (empty paths: not asked for).
inline void checkOutputPaths(std::initializer_list<std::string> paths) {
  for (const std::string& path : paths) {
    if (!path.empty()) checkOutputPath(path);
  }
}

inline void writeJsonFile(const std::string& path, const nlohmann::json& doc, int indent) {
  const std::string text = doc.dump(indent) + "\n";
  writeOutputFile(path, [&text](std::ostream& out) { out << text; });
}

inline void writePngFile(const std::string& path, const cv::Mat& image) {
  std::vector<unsigned char> png;
  if (!encodeImage(".png", image, &png)) throw Error(path + ": the plot cannot be encoded as PNG");
  writeOutputFile(path, [&png](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
}

}  // namespace pnpba::bench
