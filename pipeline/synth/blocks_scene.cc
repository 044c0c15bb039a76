#include "pipeline/synth/blocks_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "pipeline/synth/procedural_scenes.h"
#include "pipeline/synth/random.h"

namespace fresco {

Status BlocksOptions::Check() const {
  if (!(ground_m > 0.0) || !std::isfinite(ground_m)) {
    return Status::Error("blocks: ground_m must be > 0");
  }
  if (blocks < 0 || blocks > 100) return Status::Error("blocks: blocks must be in [0, 100]");
  if (!(area_m > 0.0) || !(area_m <= ground_m)) {
    return Status::Error("blocks: area_m must be in (0, ground_m]");
  }
  if (!(min_size_m > 0.0) || !(max_size_m >= min_size_m) || !(max_size_m <= area_m)) {
    return Status::Error("blocks: need 0 < min_size_m <= max_size_m <= area_m");
  }
  if (!(max_height_m >= min_size_m) || !std::isfinite(max_height_m)) {
    return Status::Error("blocks: max_height_m must be >= min_size_m");
  }
  if (texels_per_m < 8 || texels_per_m > 2048) {
    return Status::Error("blocks: texels_per_m must be in [8, 2048]");
  }
  return Status::Ok();
}

Status MakeBlocksScene(const BlocksOptions& options, Scene* scene) {
  FRESCO_RETURN_IF_ERROR(options.Check());
  *scene = Scene();
  SceneBuilder builder(scene);
  SynthRandom random(options.seed, 505);
  unsigned texture_seed = options.seed * 7919u;
  // A quad with a texture of its own, sized to its extent.
  auto add_face = [&](const std::array<Eigen::Vector3d, 4>& corners, const std::string& name) {
    const double width_m = (corners[1] - corners[0]).norm();
    const double height_m = (corners[3] - corners[0]).norm();
    auto px = [&](double m) {
      return std::clamp(static_cast<int>(std::lround(m * options.texels_per_m)), 16, 4096);
    };
    // Shapes of 2.5 to 17 cm (at the default resolution): a few pixels each from metres away.
    const double shape_px = 0.025 * options.texels_per_m;
    const int texture =
        builder.AddTexture(MakeDenseFeatureTexture(px(width_m), px(height_m), shape_px,
                                                   7.0 * shape_px, ++texture_seed),
                           name);
    builder.AddQuad(corners, builder.AddMaterial(texture, name));
  };
  using V = Eigen::Vector3d;
  const double g = 0.5 * options.ground_m;
  add_face({V(-g, 0, g), V(g, 0, g), V(g, 0, -g), V(-g, 0, -g)}, "ground");

  struct Footprint {
    double x0, z0, x1, z1;
  };
  std::vector<Footprint> placed;
  const double half_area = 0.5 * options.area_m, gap = 0.1;
  for (int tries = 0;
       tries < 50 * options.blocks && static_cast<int>(placed.size()) < options.blocks; ++tries) {
    const double w = random.Uniform(options.min_size_m, options.max_size_m);
    const double d = random.Uniform(options.min_size_m, options.max_size_m);
    const double x0 = random.Uniform(-half_area, half_area - w);
    const double z0 = random.Uniform(-half_area, half_area - d);
    const Footprint f{x0, z0, x0 + w, z0 + d};
    const bool overlaps = std::any_of(placed.begin(), placed.end(), [&](const Footprint& p) {
      return f.x0 < p.x1 + gap && p.x0 < f.x1 + gap && f.z0 < p.z1 + gap && p.z0 < f.z1 + gap;
    });
    if (overlaps) continue;
    placed.push_back(f);
    const double h = random.Uniform(options.min_size_m, options.max_height_m);
    const V a(f.x0, 0, f.z0), b(f.x1, h, f.z1);
    const std::string name = "block" + std::to_string(placed.size() - 1) + "_";
    // Sides seen from outside, upright (-Z, +Z, +X, -X), then the top (image top to -Z).
    add_face({V(b.x(), 0, a.z()), V(a.x(), 0, a.z()), V(a.x(), h, a.z()), V(b.x(), h, a.z())},
             name + "north");
    add_face({V(a.x(), 0, b.z()), V(b.x(), 0, b.z()), V(b.x(), h, b.z()), V(a.x(), h, b.z())},
             name + "south");
    add_face({V(b.x(), 0, b.z()), V(b.x(), 0, a.z()), V(b.x(), h, a.z()), V(b.x(), h, b.z())},
             name + "east");
    add_face({V(a.x(), 0, a.z()), V(a.x(), 0, b.z()), V(a.x(), h, b.z()), V(a.x(), h, a.z())},
             name + "west");
    add_face({V(a.x(), h, b.z()), V(b.x(), h, b.z()), V(b.x(), h, a.z()), V(a.x(), h, a.z())},
             name + "top");
  }
  return Status::Ok();
}

}  // namespace fresco
