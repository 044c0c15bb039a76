#include "pipeline/synth/movers.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "pipeline/synth/procedural_scenes.h"
#include "pipeline/synth/random.h"

namespace fresco {
namespace {

constexpr int kSphereStacks = 12;
constexpr int kSphereSlices = 24;

// A small vertical shading ramp (lighter on top) so movers do not look like flat cut-outs.
cv::Mat ShadingTexture(const cv::Vec3b& rgb) {
  cv::Mat rgba(32, 4, CV_8UC4);
  for (int y = 0; y < rgba.rows; ++y) {
    const double shade = 1.12 - 0.5 * y / (rgba.rows - 1.0);
    for (int x = 0; x < rgba.cols; ++x) {
      rgba.at<cv::Vec4b>(y, x) = cv::Vec4b(cv::saturate_cast<uchar>(rgb[0] * shade),
                                           cv::saturate_cast<uchar>(rgb[1] * shade),
                                           cv::saturate_cast<uchar>(rgb[2] * shade), 255);
    }
  }
  return rgba;
}

// Unit-size shape (offsets from the centre scaled by radius) as a mesh with UVs.
void AppendShape(const MoverOptions& mover, int material, Scene* scene,
                 std::vector<Eigen::Vector3d>* offsets) {
  TriangleMesh& mesh = scene->mesh;
  const int first = static_cast<int>(mesh.vertices.size());
  if (mover.shape == MoverShape::kBox) {
    Scene box;
    SceneBuilder builder(&box);
    const double r = mover.radius_m;
    builder.AddBox(Eigen::Vector3d(-r, -r, -r), Eigen::Vector3d(r, r, r), 0, 0,
                   /*with_bottom=*/true);
    for (const Eigen::Vector3d& v : box.mesh.vertices) {
      offsets->push_back(v);
      mesh.vertices.push_back(v);
    }
    for (int t = 0; t < box.mesh.NumTriangles(); ++t) {
      mesh.triangles.push_back(box.mesh.triangles[t] + Eigen::Vector3i::Constant(first));
      mesh.uvs.push_back(box.mesh.uvs[t]);
      mesh.material.push_back(material);
      mesh.has_uv.push_back(true);
    }
    return;
  }
  const int stacks = kSphereStacks, slices = kSphereSlices;
  std::vector<Eigen::Vector2f> uv;
  for (int j = 0; j <= stacks; ++j) {
    const double phi = M_PI * j / stacks;
    for (int i = 0; i <= slices; ++i) {
      const double theta = 2.0 * M_PI * i / slices;
      const Eigen::Vector3d v =
          mover.radius_m * Eigen::Vector3d(std::sin(phi) * std::cos(theta), std::cos(phi),
                                           std::sin(phi) * std::sin(theta));
      offsets->push_back(v);
      mesh.vertices.push_back(v);
      uv.emplace_back(static_cast<float>(i) / slices, static_cast<float>(j) / stacks);
    }
  }
  auto index = [&](int j, int i) { return j * (slices + 1) + i; };
  auto add = [&](int a, int b, int c) {
    mesh.triangles.emplace_back(first + a, first + b, first + c);
    mesh.uvs.push_back({uv[a], uv[b], uv[c]});
    mesh.material.push_back(material);
    mesh.has_uv.push_back(true);
  };
  for (int j = 0; j < stacks; ++j) {
    for (int i = 0; i < slices; ++i) {
      const int a = index(j, i), b = index(j + 1, i), c = index(j + 1, i + 1), d = index(j, i + 1);
      if (j > 0) add(a, d, c);  // counter-clockwise seen from outside; skip pole slivers
      if (j < stacks - 1) add(a, c, b);
    }
  }
}

}  // namespace

std::string MoverShapeName(MoverShape shape) {
  return shape == MoverShape::kBox ? "box" : "sphere";
}

bool MoverShapeFromName(const std::string& name, MoverShape* shape) {
  if (name == "sphere") {
    *shape = MoverShape::kSphere;
    return true;
  }
  if (name == "box") {
    *shape = MoverShape::kBox;
    return true;
  }
  return false;
}

Status MoverOptions::Check(const std::string& what) const {
  if (!std::isfinite(radius_m) || radius_m <= 0.0) {
    return Status::Error(what + ".radius_m: must be > 0");
  }
  if (!start.allFinite()) return Status::Error(what + ".start: not finite");
  if (!end.allFinite()) return Status::Error(what + ".end: not finite");
  if (!std::isfinite(period_frames) || period_frames <= 0.0) {
    return Status::Error(what + ".period_frames: must be > 0");
  }
  if (!std::isfinite(phase)) return Status::Error(what + ".phase: not finite");
  if (!std::isfinite(spin_deg_per_frame)) {
    return Status::Error(what + ".spin_deg_per_frame: not finite");
  }
  return Status::Ok();
}

Eigen::Vector3d MoverCentreAt(const MoverOptions& mover, int frame) {
  const double s = 0.5 - 0.5 * std::cos(2.0 * M_PI * (frame / mover.period_frames + mover.phase));
  return mover.start + s * (mover.end - mover.start);
}

double MoverSpinAt(const MoverOptions& mover, int frame) {
  return mover.spin_deg_per_frame * frame * M_PI / 180.0;
}

std::vector<MoverOptions> MakeRandomMovers(const RandomMoverOptions& options, const Camera& camera,
                                           const std::vector<Rigid3d>& cam_from_world) {
  static const cv::Vec3b kColours[] = {{255, 220, 0},  {230, 40, 40},  {40, 90, 230}, {40, 200, 80},
                                       {220, 60, 220}, {40, 210, 220}, {255, 140, 20}};
  std::vector<MoverOptions> movers;
  SynthRandom random(options.seed, 505);
  const Eigen::Vector3d lo = options.region_min.cwiseMin(options.region_max);
  const Eigen::Vector3d hi = options.region_min.cwiseMax(options.region_max);
  const double horizontal = std::min(hi.x() - lo.x(), hi.z() - lo.z());
  const double radius = std::clamp(0.06 * horizontal, 1e-3, 1.0);
  const double clearance = 1.8 * radius + 0.1 * horizontal;
  const int frames = static_cast<int>(cam_from_world.size());
  std::vector<Eigen::Vector3d> centres;
  for (const Rigid3d& pose : cam_from_world) centres.push_back(pose.Centre());

  auto sample_point = [&]() {
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) {
      const double a = lo[k] + radius, b = hi[k] - radius;
      p[k] = a < b ? random.Uniform(a, b) : 0.5 * (lo[k] + hi[k]);
    }
    // Low above the floor of the region: resting on or floating just over the ground.
    const double top = std::min(hi.y() - radius, lo.y() + radius + 0.5 * (hi.y() - lo.y()));
    p.y() = top > lo.y() + radius ? random.Uniform(lo.y() + radius, top) : lo.y() + radius;
    return p;
  };

  for (int m = 0; m < options.count; ++m) {
    MoverOptions best;
    int best_score = -1;
    for (int attempt = 0; attempt < 200; ++attempt) {
      MoverOptions c;
      c.shape = m % 2 == 0 ? MoverShape::kSphere : MoverShape::kBox;
      c.radius_m = radius;
      c.rgb = kColours[m % 7];
      c.start = sample_point();
      c.end = sample_point();
      c.end.y() = c.start.y() + random.Uniform(-0.2, 0.2) * radius;
      c.period_frames = random.Uniform(50.0, 120.0);
      c.phase = random.Uniform(0.0, 1.0);
      c.spin_deg_per_frame = c.shape == MoverShape::kBox ? random.Uniform(-3.0, 3.0) : 0.0;
      if ((c.end - c.start).norm() < 2.0 * radius) continue;
      int score = 0;
      bool collides = false;
      for (int f = 0; f < frames && !collides; ++f) {
        const Eigen::Vector3d centre = MoverCentreAt(c, f);
        if ((centre - centres[f]).norm() < clearance) collides = true;
        Eigen::Vector2d pixel;
        if (camera.Project(cam_from_world[f] * centre, &pixel) && pixel.x() >= 0 &&
            pixel.y() >= 0 && pixel.x() <= camera.width - 1 && pixel.y() <= camera.height - 1) {
          ++score;
        }
      }
      if (collides) continue;
      if (score > best_score) {
        best_score = score;
        best = c;
      }
    }
    if (best_score >= 0) movers.push_back(best);
  }
  return movers;
}

MoverScene::MoverScene(const Scene& scene, const std::vector<MoverOptions>& movers)
    : scene_(scene), movers_(movers) {
  first_triangle_ = scene_.mesh.NumTriangles();
  SceneBuilder builder(&scene_);
  for (size_t m = 0; m < movers_.size(); ++m) {
    const std::string name = "mover_" + std::to_string(m);
    const int texture =
        builder.AddTexture(ShadingTexture(movers_[m].rgb), name, TextureWrap::kClampToEdge);
    const int material = builder.AddMaterial(texture, name);
    first_vertex_.push_back(static_cast<int>(scene_.mesh.vertices.size()));
    offsets_.emplace_back();
    AppendShape(movers_[m], material, &scene_, &offsets_.back());
  }
  SetFrame(0);
}

void MoverScene::SetFrame(int frame) {
  for (size_t m = 0; m < movers_.size(); ++m) {
    const Eigen::Vector3d centre_local = scene_.LocalFromWorld(MoverCentreAt(movers_[m], frame));
    const Eigen::Matrix3d spin =
        Eigen::AngleAxisd(MoverSpinAt(movers_[m], frame), Eigen::Vector3d::UnitY())
            .toRotationMatrix();
    for (size_t k = 0; k < offsets_[m].size(); ++k) {
      scene_.mesh.vertices[first_vertex_[m] + k] = centre_local + spin * offsets_[m][k];
    }
  }
}

}  // namespace fresco
