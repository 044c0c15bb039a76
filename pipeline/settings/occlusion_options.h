// The occlusion (depth test) stage's settings: the struct the stage reads, and its fields as the
// project file, `--set`, `fresco settings`, the app's settings widgets and the docs' settings table
// see them (each with its range and help, listed once in Fields). Adding a setting is a member
// here and its line in Fields; nothing else.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "pipeline/settings/setting_rule.h"

namespace fresco {

struct OcclusionOptions {
  bool enabled = true;
  // A texel is visible when its depth is within this fraction of the rendered depth
  // (relative tolerance, scales with depth) plus `tolerance_m`.
  double tolerance_rel = 0.01;
  double tolerance_m = 0.002;
  // Texels seen at more than this angle from the surface normal are not painted.
  double max_view_angle_deg = 80.0;

  bool operator==(const OcclusionOptions&) const = default;
};

template <class V>
void Fields(OcclusionOptions& o, V& v) {
  v.Field("enabled", o.enabled, {.help = "test every texel against the video camera's depth map"});
  v.Field(
      "tolerance_rel", o.tolerance_rel,
      {.min = 0,
       .help =
           "a texel is visible when its depth is within this fraction of the rendered depth ..."});
  v.Field("tolerance_m", o.tolerance_m, {.min = 0, .help = "... plus this many metres"});
  v.Field("max_view_angle_deg", o.max_view_angle_deg,
          {.min = 0,
           .min_exclusive = true,
           .max = 90,
           .help = "texels seen at more than this angle from the surface normal (or from behind) "
                   "are not painted"});
}

}  // namespace fresco
