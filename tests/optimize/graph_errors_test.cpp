// Bad graphs fail with a clear pnpba::Error naming the culprit, never a crash; edge levels
// select the active edges as in g2o.
#include <gtest/gtest.h>

#include <cmath>

#include "pnpba/core/error.h"
#include "pnpba/optimize/camera_parameters.h"
#include "pnpba/optimize/edge_project_xyz2uv.h"
#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/sparse_optimizer.h"

namespace pnpba {
namespace {

// Asserts that `statement` throws pnpba::Error whose message contains `fragment`.
#define EXPECT_ERROR_CONTAINING(statement, fragment)                                  \
  do {                                                                                \
    try {                                                                             \
      statement;                                                                      \
      ADD_FAILURE() << "no pnpba::Error from " #statement;                            \
    } catch (const Error& e) {                                                        \
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what(); \
    }                                                                                 \
  } while (0)

VertexSE3Expmap* addPose(SparseOptimizer& opt, int id) {
  auto* v = new VertexSE3Expmap();
  v->setId(id);
  opt.addVertex(v);
  return v;
}

VertexPointXYZ* addPoint(SparseOptimizer& opt, int id, const Eigen::Vector3d& X) {
  auto* v = new VertexPointXYZ();
  v->setId(id);
  v->setEstimate(X);
  v->setMarginalized(true);
  opt.addVertex(v);
  return v;
}

EdgeSE3ProjectXYZ* makeEdge(Vertex* point, Vertex* pose, const Eigen::Vector2d& uv) {
  auto* e = new EdgeSE3ProjectXYZ();
  e->setVertex(0, point);
  e->setVertex(1, pose);
  e->setMeasurement(uv);
  e->fx = e->fy = 500, e->cx = 320, e->cy = 240;
  return e;
}

TEST(GraphErrors, DuplicateVertexIdIsRejected) {
  SparseOptimizer opt;
  addPose(opt, 3);
  auto* dup = new VertexSE3Expmap();
  dup->setId(3);
  EXPECT_ERROR_CONTAINING(opt.addVertex(dup), "duplicate vertex id 3");
  EXPECT_EQ(opt.numVertices(), 1u);
}

TEST(GraphErrors, NullVertexAndEdgeAreRejected) {
  SparseOptimizer opt;
  EXPECT_ERROR_CONTAINING(opt.addVertex(nullptr), "null vertex");
  EXPECT_ERROR_CONTAINING(opt.addEdge(nullptr), "null edge");
}

TEST(GraphErrors, EdgeOnMissingVertexIsRejected) {
  SparseOptimizer opt;
  VertexSE3Expmap* pose = addPose(opt, 0);
  // The textbook idiom optimizer.vertex(id) returns null for an id never added.
  auto* e = makeEdge(opt.vertex(42), pose, Eigen::Vector2d(1, 2));
  e->setId(7);
  EXPECT_ERROR_CONTAINING(opt.addEdge(e), "edge 7: vertex 0 is not set");
  EXPECT_EQ(opt.numEdges(), 0u);
}

TEST(GraphErrors, EdgeOnVertexOfAnotherGraphIsRejected) {
  SparseOptimizer opt, other;
  VertexSE3Expmap* pose = addPose(opt, 0);
  VertexPointXYZ* foreign = addPoint(other, 1, Eigen::Vector3d(0, 0, 2));
  auto* e = makeEdge(foreign, pose, Eigen::Vector2d(1, 2));
  e->setId(5);
  EXPECT_ERROR_CONTAINING(opt.addEdge(e), "(id 1) is not in this optimizer");
}

TEST(GraphErrors, NanMeasurementIsRejectedAtInitialization) {
  SparseOptimizer opt;
  VertexSE3Expmap* pose = addPose(opt, 0);
  VertexPointXYZ* point = addPoint(opt, 1, Eigen::Vector3d(0, 0, 2));
  auto* e = makeEdge(point, pose, Eigen::Vector2d(NAN, 2));
  e->setId(9);
  opt.addEdge(e);
  EXPECT_ERROR_CONTAINING(opt.initializeOptimization(), "edge 9: measurement");
}

TEST(GraphErrors, InfiniteEstimateIsRejected) {
  SparseOptimizer opt;
  VertexSE3Expmap* pose = addPose(opt, 0);
  VertexPointXYZ* point = addPoint(opt, 4, Eigen::Vector3d(0, INFINITY, 2));
  opt.addEdge(makeEdge(point, pose, Eigen::Vector2d(1, 2)));
  EXPECT_ERROR_CONTAINING(opt.initializeOptimization(), "vertex 4: estimate is not finite");
}

TEST(GraphErrors, MissingOrWrongParameterIsRejected) {
  SparseOptimizer opt;
  VertexSE3Expmap* pose = addPose(opt, 0);
  VertexPointXYZ* point = addPoint(opt, 1, Eigen::Vector3d(0, 0, 2));
  auto* e = new EdgeProjectXYZ2UV();
  e->setId(2);
  e->setVertex(0, point);
  e->setVertex(1, pose);
  e->setParameterId(0, 0);
  opt.addEdge(e);
  EXPECT_ERROR_CONTAINING(opt.initializeOptimization(), "parameter 0 was not added");
  opt.addParameter(new Parameter());  // id -1, not 0
  auto* wrong = new Parameter();
  wrong->setId(0);
  opt.addParameter(wrong);
  EXPECT_ERROR_CONTAINING(opt.initializeOptimization(), "must be a CameraParameters");
}

TEST(GraphErrors, SlotsAnEdgeDoesNotHaveAreNamed) {
  EdgeProjectXYZ2UV e;  // binary, one parameter
  e.setId(7);
  EXPECT_EQ(e.numVertices(), 2u);
  EXPECT_EQ(e.numParameters(), 1u);
  EXPECT_EQ(e.vertex(1), nullptr);
  EXPECT_EQ(e.parameterId(0), -1);
  EXPECT_ERROR_CONTAINING(e.setVertex(2, nullptr), "edge 7: has no vertex slot 2");
  EXPECT_ERROR_CONTAINING(e.vertex(2), "edge 7: has no vertex slot 2");
  EXPECT_ERROR_CONTAINING(e.setParameterId(1, 0), "edge 7: has no parameter slot 1");
  EXPECT_ERROR_CONTAINING(e.parameterId(-1), "edge 7: has no parameter slot -1");
}

TEST(GraphErrors, OptimizeBeforeInitializationIsRejected) {
  SparseOptimizer opt;
  addPose(opt, 0);
  EXPECT_ERROR_CONTAINING(opt.optimize(10), "before initializeOptimization");
}

// A custom binary edge between two points: the native Schur solver cannot eliminate both ends.
class EdgePointDifference
    : public BaseBinaryEdge<3, Eigen::Vector3d, VertexPointXYZ, VertexPointXYZ> {
 public:
  void evaluate(const Eigen::Vector3d& a, const Eigen::Vector3d& b, ErrorVector* error,
                JacobianXiType* Ji, JacobianXjType* Jj) const override {
    *error = measurement_ - (b - a);
    if (Ji) *Ji = Eigen::Matrix3d::Identity();
    if (Jj) *Jj = -Eigen::Matrix3d::Identity();
  }
};

TEST(GraphErrors, EdgeBetweenTwoMarginalizedVerticesIsRejectedByNativeSolver) {
  SparseOptimizer opt;
  opt.setSolverBackend(SolverBackend::kNative);
  VertexPointXYZ* a = addPoint(opt, 1, Eigen::Vector3d(0, 0, 1));
  VertexPointXYZ* b = addPoint(opt, 2, Eigen::Vector3d(0, 0, 2));
  auto* e = new EdgePointDifference();
  e->setId(3);
  e->setVertex(0, a);
  e->setVertex(1, b);
  opt.addEdge(e);
  opt.initializeOptimization();
  EXPECT_ERROR_CONTAINING(opt.optimize(5), "edge 3 joins two marginalized vertices");
}

TEST(GraphErrors, EdgeLevelsSelectTheActiveEdges) {
  SparseOptimizer opt;
  VertexSE3Expmap* pose = addPose(opt, 0);
  VertexPointXYZ* p1 = addPoint(opt, 1, Eigen::Vector3d(0, 0, 2));
  VertexPointXYZ* p2 = addPoint(opt, 2, Eigen::Vector3d(1, 0, 2));
  auto* e1 = makeEdge(p1, pose, Eigen::Vector2d(323, 240));  // error (3, 0): chi2 9
  auto* e2 = makeEdge(p2, pose, Eigen::Vector2d(570, 244));  // error (0, 4): chi2 16
  e2->setLevel(1);
  opt.addEdge(e1);
  opt.addEdge(e2);
  opt.initializeOptimization(0);
  opt.computeActiveErrors();
  EXPECT_EQ(opt.activeEdges().size(), 1u);
  EXPECT_NEAR(opt.chi2(), 9.0, 1e-12);
  opt.initializeOptimization(1);
  opt.computeActiveErrors();
  EXPECT_NEAR(opt.chi2(), 16.0, 1e-12);
}

TEST(GraphErrors, InvalidOptionsAreNamed) {
  OptimizerOptions o;
  EXPECT_EQ(o.validate(), "");
  o.tau = -1;
  EXPECT_EQ(o.validate(), "tau must be > 0");
  EXPECT_ERROR_CONTAINING(parseSolverBackend("g2o"), "unknown solver 'g2o'");
}

}  // namespace
}  // namespace pnpba
