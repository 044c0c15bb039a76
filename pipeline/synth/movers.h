// Moving objects for synthetic captures (like the paper's yellow sphere, fig. 6): coloured
// spheres and boxes that move back and forth along a segment. They are added to a COPY of
// the scene used for rendering frames only; the scene written for a project never has them.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"

namespace fresco {

enum class MoverShape { kSphere, kBox };
std::string MoverShapeName(MoverShape shape);  // "sphere" | "box"
bool MoverShapeFromName(const std::string& name, MoverShape* shape);

struct MoverOptions {
  MoverShape shape = MoverShape::kSphere;
  double radius_m = 0.3;                   // sphere radius; half the box's edge
  cv::Vec3b rgb = cv::Vec3b(255, 220, 0);  // the paper's yellow sphere
  // The centre moves start -> end -> start ... smoothly (cosine ease), world coordinates.
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d end = Eigen::Vector3d::Zero();
  double period_frames = 60.0;      // one full start -> end -> start cycle
  double phase = 0.0;               // fraction of the period at frame 0 (0 = at start)
  double spin_deg_per_frame = 0.0;  // rotation about +Y (boxes show it)

  Status Check(const std::string& what) const;  // `what` names it in messages: "movers[0]"
};

// The mover's centre (world) and its rotation about +Y (radians) at `frame`.
Eigen::Vector3d MoverCentreAt(const MoverOptions& mover, int frame);
double MoverSpinAt(const MoverOptions& mover, int frame);

// Places `count` movers automatically inside the axis-aligned region [region_min,
// region_max] (world): each moves along a random segment at a random speed, never comes
// within reach of the camera (its centre stays > 1.8 radius + 10 % of the region's smaller
// horizontal extent from the camera centre at every frame), and is picked among many
// candidates for being in view (by the true poses) in as many frames as possible. Radius:
// 6 % of the region's smaller horizontal extent (at most 1 m). Deterministic for `seed`.
// Fewer than `count` come back when no candidate keeps clear of the camera.
struct RandomMoverOptions {
  int count = 0;
  Eigen::Vector3d region_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d region_max = Eigen::Vector3d::Zero();
  unsigned seed = 1;
};
std::vector<MoverOptions> MakeRandomMovers(const RandomMoverOptions& options, const Camera& camera,
                                           const std::vector<Rigid3d>& cam_from_world);

// A copy of a scene with the movers' triangles appended (one material and a small shading
// texture per mover). SetFrame moves them; triangles from FirstMoverTriangle() on belong to
// movers.
class MoverScene {
 public:
  MoverScene(const Scene& scene, const std::vector<MoverOptions>& movers);
  void SetFrame(int frame);
  const Scene& scene() const { return scene_; }
  int FirstMoverTriangle() const { return first_triangle_; }

 private:
  Scene scene_;
  std::vector<MoverOptions> movers_;
  int first_triangle_ = 0;
  // Per mover: its vertices' offsets from the centre (unrotated) and where they start.
  std::vector<std::vector<Eigen::Vector3d>> offsets_;
  std::vector<int> first_vertex_;
};

}  // namespace fresco
