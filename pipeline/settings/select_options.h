// The view selection stage's settings: the struct the stage reads, and its fields as the project
// file, `--set`, `fresco settings`, the app's settings widgets and the docs' settings table
// see them (each with its range and help, listed once in Fields). Adding a setting is a member
// here and its line in Fields; nothing else.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "pipeline/settings/setting_rule.h"

namespace fresco {

// View selection and colour consistency for real photos (pipeline/paint/view_select.h), the
// `select` stage between background and paint: per frame a gain per colour channel,
// estimated against what the buffers already hold (median ratio over the texels both have)
// and divided out before painting; a score per texel (pixels per texel times the cosine of
// the view angle, uncapped, blended with the frame's median score over the buffer so that a
// region keeps one frame), much lower where the texel is seen near a depth discontinuity of
// the frame's depth map (silhouettes: where a mesh a few pixels off paints background); a
// painted texel takes a new frame's sample only when it scores clearly better.
struct SelectOptions {
  bool enabled = false;      // off: the quality policy alone (`update`, `quality_slack`); on costs
                             // 2-4 times the warp stage (real photos: docs/results.md)
  bool exposure = true;      // divide out each frame's gain against the buffers
  bool level_seams = false;  // level each frame's colours locally against the buffers
  int level_cell_texels = 16;   // ... in cells of this many texels a side, fading as far
  double switch_margin = 0.25;  // a painted texel switches frame when the score is this much better
  double region_weight = 0.5;   // 0: the texel's own score; 1: the frame's median over the buffer
  double edge_px = 6.0;         // texels seen within this many pixels of a depth discontinuity
  double edge_penalty = 0.1;    // ... have their score multiplied by this
  double edge_depth_rel = 0.05;  // neighbouring pixels whose depths differ by this fraction

  bool operator==(const SelectOptions&) const = default;
};

template <class V>
void Fields(SelectOptions& o, V& v) {
  v.Field(
      "enabled", o.enabled,
      {.help =
           "score every view of a texel and keep the better one, and match exposures (below): for "
           "real photos with changing exposure (on the Sceaux castle photos +0.9 to 1.1 dB and 1 - "
           "NCC 0.07 lower, at 2-4 times the warp stage's cost); it runs with `update: quality` "
           "and `refine.mode` `off` or `auto` (which then decides off: refinement moves the "
           "buffers to the frames and needs them to take new samples); it also caps the background "
           "model's warm-up at a third of the "
           "capture's frames. Off (the default): `update` and `quality_slack` alone decide"});
  v.Field("exposure", o.exposure,
          {.help = "per frame, a gain per colour channel against what the buffers already hold "
                   "(the median ratio over the texels both have) is divided out before painting: "
                   "one consistent exposure, set by the first frames"});
  v.Field("level_seams", o.level_seams,
          {.help = "where a frame's new samples meet texels that keep their stored sample, the new "
                   "ones are levelled to continue the kept colours (per cell of "
                   "`level_cell_texels`, the median ratio), fading to the frame's own colours "
                   "over as many texels: fewer seams where the painting passes from one photo to "
                   "the next, for light that changes across a photo (vignetting, haze, flare); "
                   "on the Sceaux castle photos 1 - NCC 0.006-0.007 lower, PSNR within 0.01 dB"});
  v.Field("level_cell_texels", o.level_cell_texels,
          {.min = 4,
           .max = 1024,
           .help = "the levelling's cells, texels a side, and how far its correction fades: "
                   "larger removes wider seams but carries one photo's light further into the "
                   "next"});
  v.Field("switch_margin", o.switch_margin,
          {.min = 0,
           .max = 10,
           .help = "a painted texel takes a new frame's sample only when that view scores this "
                   "much better (0.25: 25 %): fewer switches between frames, fewer seams"});
  v.Field("region_weight", o.region_weight,
          {.min = 0,
           .max = 1,
           .help = "a view's score blends the texel's own (pixels per texel times the cosine of "
                   "the view angle) with the frame's median over the chart: 0 per texel, 1 per "
                   "chart (a chart tends to keep one frame)"});
  v.Field("edge_px", o.edge_px,
          {.min = 0,
           .max = 100,
           .help = "texels seen within this many pixels of a depth discontinuity of the frame (a "
                   "silhouette, where a slightly wrong mesh samples the background) ..."});
  v.Field("edge_penalty", o.edge_penalty,
          {.min = 0,
           .max = 1,
           .help = "... score this times less: they fill texels no better view has painted, and "
                   "the next good view replaces them"});
  v.Field("edge_depth_rel", o.edge_depth_rel,
          {.min = 0,
           .min_exclusive = true,
           .max = 10,
           .help = "neighbouring pixels whose depths differ by this fraction of the nearer one "
                   "make a discontinuity (surface beside no surface always does)"});
}

}  // namespace fresco
