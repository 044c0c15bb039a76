// The painting settings as plain data, the ground floor every layer includes: the pipeline's
// options (every stage's struct beside it in this folder) and the list of their fields as the
// project file names them. core's project reader (pipeline/core/project.cc) reads and writes
// them by these lists; the painter (pipeline/paint) reads the structs.
#pragma once

#include "pipeline/settings/atlas_options.h"
#include "pipeline/settings/background_options.h"
#include "pipeline/settings/layers_options.h"
#include "pipeline/settings/occlusion_options.h"
#include "pipeline/settings/refine_options.h"
#include "pipeline/settings/select_options.h"
#include "pipeline/settings/setting_rule.h"

namespace fresco {

enum class SamplingMode { kNearest, kBilinear, kArea };
// kLatest: every visible sample overwrites (the paper). kQuality: a sample overwrites only
// when it is at least (1 - quality_slack) as sharp (pixels per texel) as the stored one.
// kMean: each texel the mean of every sample it took, weighted by pixels per texel.
// kAuto: kQuality or kMean, whichever agrees better with frames held out of the decision
// (PaintSession::DecideUpdate).
enum class UpdatePolicy { kLatest, kQuality, kMean, kAuto, kSharpMean };

struct PipelineOptions {
  SamplingMode sampling = SamplingMode::kBilinear;
  double texel_size_m = 0.0;            // base-buffer texel edge in metres; 0 = automatic
  int max_buffer_texels = 1024 * 1024;  // per base buffer; bigger groups get coarser texels
  int update_every = 1;  // paint every N-th frame (the paper used 20 with refinement)
  UpdatePolicy update = UpdatePolicy::kAuto;
  double quality_slack = 0.2;  // kQuality: accept samples this much blurrier than stored
  // Weight of an accepted sample against what the texel holds (1 = replace, the paper's;
  // below 1 = running average, which averages out the frames' residual misalignment).
  double update_weight = 1.0;
  int max_frames = 0;         // 0 = all frames
  int threads = 0;            // 0 = all cores
  bool debug_images = false;  // write per-stage debug images (costs time)
  OcclusionOptions occlusion;
  RefineOptions refine;
  BackgroundOptions background;
  AtlasOptions atlas;
  SelectOptions select;
  ViewLayerOptions layers;

  bool operator==(const PipelineOptions&) const = default;
};

inline const EnumNames<SamplingMode>& SamplingNames() {
  static const EnumNames<SamplingMode> names = {
      {SamplingMode::kNearest, "nearest"},
      {SamplingMode::kBilinear, "bilinear"},
      {SamplingMode::kArea, "area"},
  };
  return names;
}

inline const EnumNames<UpdatePolicy>& UpdatePolicyNames() {
  static const EnumNames<UpdatePolicy> names = {
      {UpdatePolicy::kLatest, "latest"}, {UpdatePolicy::kQuality, "quality"},
      {UpdatePolicy::kMean, "mean"},     {UpdatePolicy::kSharpMean, "sharp_mean"},
      {UpdatePolicy::kAuto, "auto"},
  };
  return names;
}

template <class V>
void Fields(PipelineOptions& o, V& v) {
  v.Enum("sampling", o.sampling, SamplingNames(),
         "how a texel samples the frame: nearest pixel, bilinear (the paper's §3.2), or `area` "
         "(bilinear on the pyramid level matching the texel's footprint: far or oblique views)");
  v.Field("texel_size_m", o.texel_size_m,
          {.min = 0,
           .help = "texel edge in metres; 0 = automatic: median depth the cameras see over the "
                   "focal length (one texel per pixel at the typical distance)"});
  v.Field("max_buffer_texels", o.max_buffer_texels,
          {.min = 1,
           .help = "a bigger base buffer gets coarser texels (memory is bounded: buffers are "
                   "fixed-size, frames are streamed)"});
  v.Field("update_every", o.update_every,
          {.min = 1, .help = "paint every N-th frame (the paper's §4)"});
  v.Enum("update", o.update, UpdatePolicyNames(),
         "`latest` (the paper: every visible sample overwrites), `quality` (a sample overwrites "
         "only if at least `1 - quality_slack` as sharp, in pixels per texel up to 1), `mean` "
         "(each texel the mean of every sample it took, weighted by pixels per texel up to 1: "
         "for views of a static scene that disagree in light, noise and by a few pixels; 16 "
         "more bytes per texel), `sharp_mean` (the same mean with each sample weighted by the "
         "pixels its view has on the texel, pixels per texel squared: near, head-on views "
         "count more) or `auto`: the capture is painted each way, and also each way without 6 "
         "frames spread over it (every N / 7-th of N frames; live: 2, 6, ..., 22); after the "
         "6th the model painted each way without them is rendered at their poses, and the way "
         "that agrees better with them paints on (`sharp_mean` only where it beats `mean` by "
         "0.1 dB a frame, every view alike being the safer mean, and not with view layers; "
         "where "
         "`background.mode` `auto` turned the model on, the mean without it is one more way, "
         "which turns it off; with the model on by hand, refinement on or view selection, "
         "`auto` keeps `quality`). The choice and its evidence (dB gained) are in "
         "metrics.json under `auto.update`");
  v.Field(
      "quality_slack", o.quality_slack,
      {.min = 0,
       .max = 1,
       .help = "with `update: quality`, accept samples this much blurrier than the stored one"});
  v.Field(
      "update_weight", o.update_weight,
      {.min = 0.01,
       .max = 1,
       .help =
           "weight of an accepted sample against what the texel holds: 1 replaces (the paper's); "
           "below 1 keeps a running average, which averages out residual misalignment"});
  v.Field("max_frames", o.max_frames, {.min = 0, .help = "stop after this many frames (0 = all)"});
  v.Field("threads", o.threads, {.min = 0, .help = "threads for the stages (0 = all cores)"});
  v.Field("debug_images", o.debug_images,
          {.help = "make per-stage debug images (`fresco run --debug-images` writes them under "
                   "`stages/`; costs time)"});
  v.Object("occlusion", o.occlusion);
  v.Object("refine", o.refine);
  v.Object("background", o.background);
  v.Object("atlas", o.atlas);
  v.Object("select", o.select);
  v.Object("layers", o.layers);
}

}  // namespace fresco
