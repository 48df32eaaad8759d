#include "landmark_elimination.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace pnpba {
#include "landmark_elimination_impl.h"
}  // namespace pnpba
