// A deterministic synthetic RGB-D scene with exact ground truth: a room-like set of textured
// rectangles (floor, walls, boxes) with texture rich enough for ORB, rendered by ray casting
// through a pinhole camera with optional OpenCV distortion, and a Kinect-like depth image
// (16-bit, value = z * depth_scale, noise sigma_z = noise_k z^2, holes).
// World frame = camera 1 frame; poses are T_cw (world -> camera).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "pnpba/features/pinhole_camera.h"
#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

// The rendering camera: pinhole with optional distortion, image size, depth units per metre.
struct SyntheticCamera {
  PinholeCamera pinhole;  // defaults: the textbook pair (520.9, 521.0, 325.1, 249.7)
  int width = 640, height = 480;
  double depth_scale = 5000.0;  // depth value per metre (TUM 5000, others 1000)
  // Colour averaged over n x n rays spread over each pixel, as a lens integrates over it; 1:
  // the pixel's centre alone (the default, and what every rendered figure in docs/ used). A
  // centre sample of a texture finer than the pixels aliases, and aliased images do not keep
  // their brightness between views (docs/two_view.md, the covariance). Depth is the centre's
  // either way. n > 1 needs a camera without distortion.
  int colour_samples = 1;
};

struct DepthNoise {
  double noise_k = 0.0015;      // 1/m: sigma_z = k z^2
  double hole_fraction = 0.02;  // pixels dropped at random (value 0)
  double max_range = 6.0;       // m: farther is 0, as a sensor reports
};

struct RenderedView {
  cv::Mat colour;  // CV_8UC3
  cv::Mat depth;   // CV_16UC1
};

// kOpenRoom: the sample's room (floor, three walls, a box, panels) seen from the origin along
// +z; it stays exactly as it was so data/images/ and the tests' figures do not move.
// kClosedRoom: a closed 9 x 3.5 x 9.5 m room (ceiling, four walls) with boxes, a table and
// slanted panels, so that a camera anywhere within 2 m of the origin, turned any way, sees
// surfaces with depth structure (for wide baselines and depth-only registration).
// kCabinet: a plain cabinet (1.2 x 1.0 x 0.7 m) on a floor, 3 m ahead of camera 1, with a wall
// behind it and one to its right, and nothing else: a few large planes, as in TUM
// fr3_cabinet, where depth alone leaves slides and colour has only the faces' shading and edges.
// It has no poster in either texture.
// kFreeCabinet: the same cabinet standing free on a floor, nothing else, three dark handles on the
// face toward camera 1: a half turn about its vertical axis maps everything but the handles onto
// itself, as in TUM fr3_cabinet seen from the far side (orbitMotion circles it).
// kStructure: a zig-zag of eight plain panels (0.6 m wide, 0.9 m tall, turned +-40 degrees
// about the vertical) standing on a plain floor 2.6-3.1 m ahead of camera 1, nothing else, as
// in TUM fr3_structure_notexture: the geometry repeats every two panels (1.2 m along x), so a
// slide by one period fits the depths and the faces' shading everywhere but the two ends.
// kCorridor: a plain wall 3 m ahead of camera 1 standing on a plain floor, both 16 m long along
// x, nothing else: a slide along x changes neither the depths nor the colours, whose one edge
// (where the wall meets the floor) runs along it; a corridor with plain walls seen across.
// kPoster: one plane and nothing else: a plain wall 3 m ahead of camera 1 with a poster 3.41 m
// square (the texture once, not repeated) on it, centred ahead, as the textured floor of TUM
// fr3_nostructure_texture: the depths fix only the plane's distance and tilt, and the poster's
// colours the rest. The poster is texture 0, tiled with kTiled and rich otherwise (with kPoor
// too: the poor room's one poster is texture 0 as well).
enum class SceneLayout {
  kOpenRoom,
  kClosedRoom,
  kCabinet,
  kFreeCabinet,
  kStructure,
  kCorridor,
  kPoster
};
// kRich: every surface carries a random texture full of corners. kPoor: large plain surfaces
// (one flat colour each, lit by a soft gradient) and a single small poster: few keypoints, as
// in a bare indoor room, while the geometry stays. kTiled: kRich's textures cut to a 0.5 m
// square tile repeated over every surface (wallpaper, floor tiles): each corner has twins half a
// metre apart, so matches can pair a patch with its neighbour's copy and agree on a pose shifted
// by whole tiles.
enum class SceneTexture { kRich, kPoor, kTiled };

class SyntheticScene {
 public:
  explicit SyntheticScene(unsigned seed = 7, SceneLayout layout = SceneLayout::kOpenRoom,
                          SceneTexture texture = SceneTexture::kRich);

  // Renders the scene from pose T_cw with `camera` (its distortion applied to the image).
  RenderedView render(const SyntheticCamera& camera, const SE3Quat& T_cw, const DepthNoise& noise,
                      unsigned noise_seed) const;

  // A rigid object that can move between two renders (a person walking through the view, a
  // cart, a door): an axis-aligned box from corner `low` with sizes `size`, with a corner-rich
  // texture of its own drawn from `texture_seed` whatever the scene's texture (a person's
  // clothes in a bare room). Returns its id for withObjectMoved.
  int addObject(const Eigen::Vector3d& low, const Eigen::Vector3d& size, unsigned texture_seed);
  // A copy of this scene with object `id` moved by `motion` (a rigid motion in world
  // coordinates about the box's centre: rotation, then translation). Throws std::out_of_range
  // for an id addObject did not return.
  SyntheticScene withObjectMoved(int id, const SE3Quat& motion) const;

  // The textbook-like pair: camera 1 at the origin, camera 2 moved by about 3 degrees and
  // 12 cm. Returns T_21.
  static SE3Quat defaultMotion();

  // A motion T_21 of camera 2 from camera 1 whose centre moves exactly `translation_m` and which
  // turns by exactly `rotation_deg` about `axis` (normalised), with the centre placed where
  // camera 2's optical axis passes as close as it can to the point 3 m ahead of camera 1:
  // the way a person walks around what they film.
  static SE3Quat lookAtMotion(double rotation_deg, const Eigen::Vector3d& axis,
                              double translation_m);

  // A motion T_21 of camera 2 from camera 1 that circles the free cabinet (kFreeCabinet) by
  // `degrees` about its vertical axis, camera 2 looking at it as camera 1 does: at 180 it sees
  // the cabinet's back from as far away.
  static SE3Quat orbitMotion(double degrees);

 private:
  struct Quad {
    Eigen::Vector3d origin, axis_u, axis_v;  // point = origin + s u + t v, s,t in [0, 1]
    int texture = 0;
  };
  void buildOpenRoom();
  void buildClosedRoom();
  void buildCabinet();
  void buildFreeCabinet();
  void buildStructure();
  void buildCorridor();
  void buildPoster();
  // An axis-aligned box from corner `low` with sizes `size`, all six faces, one texture.
  void addBox(const Eigen::Vector3d& low, const Eigen::Vector3d& size, int texture);
  // Nearest hit along the ray: depth parameter and colour; false if none.
  bool castRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double* distance,
               cv::Vec3b* colour) const;

  struct Object {
    size_t first_quad, end_quad;  // its faces: quads_[first_quad, end_quad)
    Eigen::Vector3d centre;
  };

  std::vector<Quad> quads_;
  std::vector<cv::Mat> textures_;  // CV_8UC3
  std::vector<Object> objects_;
  bool shade_faces_ = false;  // closed room: per-face Lambertian shading
};

}  // namespace pnpba
