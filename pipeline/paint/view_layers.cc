#include "pipeline/paint/view_layers.h"

#include <cmath>

namespace fresco {

LayerChoice ChooseViewLayer(const std::vector<ViewLayer>& layers,
                            const Eigen::Vector3d& scene_centre,
                            const Eigen::Vector3d& camera_centre, const ViewLayerOptions& options) {
  LayerChoice choice;
  const Eigen::Vector3d d = camera_centre - scene_centre;
  if (d.norm() > 0) choice.direction = d.normalized();
  double best_cos = -2;
  for (size_t i = 0; i < layers.size(); ++i) {
    const double c = layers[i].direction.dot(choice.direction);
    if (c > best_cos) best_cos = c, choice.index = i;
  }
  const double min_cos = std::cos(options.min_angle_deg * M_PI / 180.0);
  if (!layers.empty() && best_cos >= min_cos) return choice;  // joins the nearest
  choice.fresh = true;
  if (static_cast<int>(layers.size()) < options.count) {
    choice.index = layers.size();
    return choice;
  }
  // Full: the pair of layers nearest each other gives up the one with fewer frames, unless the
  // new direction is nearer its nearest layer than that pair (then it joins it).
  double pair_cos = -2;
  size_t a = 0, b = 0;
  for (size_t i = 0; i < layers.size(); ++i)
    for (size_t j = i + 1; j < layers.size(); ++j) {
      const double c = layers[i].direction.dot(layers[j].direction);
      if (c > pair_cos) pair_cos = c, a = i, b = j;
    }
  if (layers.size() < 2 || best_cos >= pair_cos) {
    choice.fresh = false;
    return choice;
  }
  choice.index = layers[a].frames <= layers[b].frames ? a : b;
  return choice;
}

}  // namespace fresco
