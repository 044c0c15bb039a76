// What the COLMAP tests share (`fresco poses` and the app's New project bootstrap): the skip
// when the `colmap` program is absent, a small synthetic capture COLMAP registers (boxes on
// a ground, every face its own dense feature texture, seen from a half orbit: parallax
// everywhere), its scene size and true poses, and control points made from the truth.
#pragma once

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "pipeline/core/camera.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/run_process.h"
#include "pipeline/core/scene.h"
#include "tests/test_support.h"

namespace fresco::testing {

#define FRESCO_REQUIRE_COLMAP()                                                   \
  do {                                                                            \
    if (::fresco::FindProgram("colmap").empty())                                  \
      GTEST_SKIP() << "`colmap` is not on PATH (Debian package colmap): skipped"; \
  } while (0)

// `fresco synth` of builtin:blocks into `dir`: `frames` frames of 480x360 on half an orbit
// (truth in DIR/truth/images.txt; DIR/project.json paints it). COLMAP registers every frame
// with 1000 features per image: 16 in about 15 s on 2 cores, 12 in 19 s on a loaded machine.
inline CommandResult SynthBlocks(const std::string& dir, int frames) {
  return RunFresco({"synth", "--scene", "builtin:blocks", "--out", dir, "--frames",
                    std::to_string(frames), "--size", "480x360", "--supersample", "2", "--seed",
                    "3", "--path", "orbit", "--set", "path.turns=0.5"});
}

// The diagonal of the bounding box of `dir`/scene.gltf (metres).
inline double SceneSizeM(const std::string& dir) {
  Scene scene;
  EXPECT_TRUE(LoadGltfScene(dir + "/scene.gltf", SceneLoadOptions(), &scene).ok()) << dir;
  Eigen::Vector3d lo, hi;
  scene.Bounds(&lo, &hi);
  return (hi - lo).norm();
}

// Known points of builtin:blocks, on the ground and above it.
inline std::vector<Eigen::Vector3d> BlocksControlPoints() {
  return {{-1.5, 0.0, -1.0}, {1.5, 0.0, -1.2}, {1.2, 0.0, 1.5}, {-1.0, 1.0, 0.5}, {0.3, 1.5, -0.2}};
}

// A control-point file: NAME X Y Z (`written`) then (IMAGE U V) in 2-3 frames where the true
// point (`world`) projects; `points`: how many lines it has (points seen at least twice).
inline std::string ControlPointsText(const std::vector<Eigen::Vector3d>& world,
                                     const std::vector<Eigen::Vector3d>& written,
                                     const std::vector<PosedImage>& truth, const Camera& camera,
                                     int* points) {
  std::string text = "# name X Y Z image u v ...\n";
  *points = 0;
  const int frames = static_cast<int>(truth.size());
  for (size_t k = 0; k < world.size(); ++k) {
    char head[128];
    std::snprintf(head, sizeof(head), "p%zu %.6f %.6f %.6f", k, written[k].x(), written[k].y(),
                  written[k].z());
    std::string line = head;
    int seen = 0;
    for (int i = static_cast<int>(k) % 3; i < frames && seen < 3; i += 5) {
      Eigen::Vector2d px;
      if (!camera.Project(truth[i].cam_from_world * world[k], &px)) continue;
      if (px.x() < 0 || px.y() < 0 || px.x() > camera.width - 1 || px.y() > camera.height - 1)
        continue;
      char obs[96];
      std::snprintf(obs, sizeof(obs), " %s %.4f %.4f", truth[i].name.c_str(), px.x(), px.y());
      line += obs;
      ++seen;
    }
    if (seen >= 2) {
      text += line;
      text += '\n';
      ++*points;
    }
  }
  return text;
}

// Posed frames of `got` against `truth` (by name): the largest rotation (deg) and centre (m)
// errors; a frame the truth lacks is a failure.
struct PoseErrors {
  int posed = 0;
  double max_rotation_deg = 0.0, max_position_m = 0.0;
};
inline PoseErrors CompareWithTruth(const std::vector<PosedImage>& got,
                                   const std::vector<PosedImage>& truth) {
  PoseErrors e;
  for (const PosedImage& g : got) {
    const PosedImage* t = nullptr;
    for (const PosedImage& candidate : truth)
      if (candidate.name == g.name) t = &candidate;
    if (t == nullptr) {
      ADD_FAILURE() << g.name << ": not in the truth";
      continue;
    }
    ++e.posed;
    e.max_rotation_deg =
        std::max(e.max_rotation_deg,
                 RotationDifferenceDeg(g.cam_from_world.rotation, t->cam_from_world.rotation));
    e.max_position_m =
        std::max(e.max_position_m, (g.cam_from_world.Centre() - t->cam_from_world.Centre()).norm());
  }
  return e;
}

}  // namespace fresco::testing
