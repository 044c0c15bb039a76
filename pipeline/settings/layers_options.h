// The view-dependent layers' settings: the struct the layers stage reads, and its fields as the
// project file, `--set`, `fresco settings`, the app's settings widgets and the docs' settings
// table see them (each with its range and help, listed once in Fields).
#pragma once

#include "pipeline/settings/setting_rule.h"

namespace fresco {

// Views that change with the viewer (view_layers.h): besides the base buffers, up to `count`
// layers of the same texels, each painted only from the frames that look at the scene from
// one direction; a render blends, per pixel, the layers whose frames looked from nearest the
// viewer's direction (the base texture where no layer has paint).
struct ViewLayerOptions {
  int count = 0;             // 0: no layers (one texture, the default)
  double min_angle_deg = 5;  // a frame starts a new layer when its direction from the scene's
                             // centre is this far from every layer's

  bool operator==(const ViewLayerOptions&) const = default;
};

template <class V>
void Fields(ViewLayerOptions& o, V& v) {
  v.Field("count", o.count,
          {.min = 0,
           .max = 64,
           .help = "layers painted each from the frames of one viewing direction, blended by the "
                   "viewer's direction when the model is rendered (`fresco rephoto`): the look of "
                   "the nearest photos (sun, haze, gloss) where one texture averages them; each "
                   "layer costs 4-8 bytes per texel and a paint pass per frame. 0: one texture"});
  v.Field("min_angle_deg", o.min_angle_deg,
          {.min = 0,
           .max = 180,
           .help = "a frame whose direction from the scene's centre is this far from every "
                   "layer's starts a new layer; with `count` layers made, it replaces the layer "
                   "with fewer frames of the two nearest each other (when they are nearer each "
                   "other than the frame is to any); otherwise the frame joins the nearest"});
}

}  // namespace fresco
