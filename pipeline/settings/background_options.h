// The background stage's settings: the struct the stage reads, and its fields as the project
// file, `--set`, `fresco settings`, the app's settings widgets and the docs' settings table
// see them (each with its range and help, listed once in Fields). Adding a setting is a member
// here and its line in Fields; nothing else.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "pipeline/settings/setting_rule.h"

namespace fresco {

// Selective painting (paper §3.4): a per-texel background model in base-buffer space (so it
// works for moving cameras); texels whose sample differs from it are foreground and are not
// painted. kAverage: the paper's linear average of each texel's first `training_frames`
// samples, then image subtraction with a fixed `average_threshold`. kRobust: two colour
// modes per texel with weights over a sliding window (background = the heavier mode, so
// it converges to what the texel shows most of the time, whatever came first), an adaptive
// per-texel noise threshold and a per-frame global gain (exposure) estimate. kAuto: kRobust
// where the capture shows movers, else kOff, decided before painting for captures from
// files (the movers found across views), over the first frames otherwise (auto_modes.h).
enum class BackgroundMode { kOff, kAverage, kRobust, kAuto };
enum class GrowMode { kOff, kOn, kAuto };

struct BackgroundOptions {
  BackgroundMode mode = BackgroundMode::kAuto;
  // kAverage: samples averaged per texel before it segments (at most 250), and the
  // foreground threshold on the largest channel difference, grey levels.
  int training_frames = 20;
  double average_threshold = 30.0;
  // kRobust: a texel's samples before its model is trusted. Until then what it paints is
  // provisional (any later background sample replaces it, whatever its quality).
  int warmup_frames = 8;
  // kRobust: the learning window in samples: weights follow the last ~N samples, so an
  // object that stops for ~N/2 of them becomes background, and the background it hid comes
  // back ~N/2 samples after it leaves; lighting drift is followed too. Measured (README):
  // 40 beats 100 and 300 on the static-camera clips, where people stand for a long time.
  int window_frames = 40;
  // kRobust: the share of a texel's recent samples its background mode must explain for the
  // model to judge them. Below it (the texel shows two things about equally often: a slow or
  // large mover over it for as long as not, a misaligned edge) its samples are neither
  // masked nor trusted but painted provisionally, the sharpest kept, as without a model.
  // Measured over the evaluation suite (docs/results.md): 0.6 against 0.7 and 0.8.
  double majority = 0.6;
  // kRobust: foreground beyond `sigma_threshold` standard deviations of the texel's noise
  // (RMS over channels), the noise never counted below `min_sigma` grey levels.
  double sigma_threshold = 3.0;
  double min_sigma = 6.0;
  // kRobust: divide each frame by its global gain (median sample/background ratio).
  bool normalize_gain = true;
  // Mask cleaning (both models): foreground blobs smaller than this are background
  // (noise), and the rest is dilated by this margin (blurred edges, shadows).
  int min_blob_texels = 12;
  int dilate_texels = 2;
  // Foreground grown by colour (foreground_grow.h): from the flagged texels that survive
  // cleaning into neighbouring sampled texels within `grow_levels` grey levels of them (every
  // channel), up to `grow_reach_texels` away. kAuto: once the refinement's `auto` has
  // measured the frames and found them aligned (misaligned samples flag thin edges, and
  // growing those masks whole regions of a static scene; on the castle's 10 photos, which it
  // cannot measure, growing left holes). Measured over both evaluation suites
  // (docs/results.md).
  GrowMode grow = GrowMode::kAuto;
  double grow_levels = 32.0;
  int grow_reach_texels = 256;
  // Captures from files, with a model: the movers found across views before painting
  // (mover_masks.h) that touch the foreground the model flags in a buffer join it there,
  // where it grows (`grow`), and the pixels they cover are not painted there (with `grow`
  // `auto`, also while refinement's `auto` is deciding: in the first two frames and once it
  // has measured a frame).
  // Measured over both evaluation suites (docs/results.md).
  bool across_views = true;
  // ... and the pixels around them, out to this share of the frame's longer side, are not
  // painted either (they are not the model's foreground): where the frames near a mover
  // disagree about which side of an edge is the mover, its edge pixels and the background it
  // just uncovered are the ones painting took it from. 0: none.
  double mover_margin = 0.0125;

  bool operator==(const BackgroundOptions&) const = default;
};

// Whether a capture from files is compared across views before painting (mover_masks.h): for
// `auto`'s decision, or for `across_views` with a model.
inline bool NeedsMoversAcrossViews(const BackgroundOptions& o) {
  return o.mode == BackgroundMode::kAuto || (o.across_views && o.mode != BackgroundMode::kOff);
}

inline const EnumNames<BackgroundMode>& BackgroundModeNames() {
  static const EnumNames<BackgroundMode> names = {
      {BackgroundMode::kOff, "off"},
      {BackgroundMode::kAverage, "average"},
      {BackgroundMode::kRobust, "robust"},
      {BackgroundMode::kAuto, "auto"},
  };
  return names;
}

inline const EnumNames<GrowMode>& GrowModeNames() {
  static const EnumNames<GrowMode> names = {
      {GrowMode::kOff, "off"},
      {GrowMode::kOn, "on"},
      {GrowMode::kAuto, "auto"},
  };
  return names;
}

template <class V>
void Fields(BackgroundOptions& o, V& v) {
  v.Enum("mode", o.mode, BackgroundModeNames(),
         "`average` is the paper's (§3.4); `robust` follows changes and exposure; `auto` (the "
         "default): `robust` where the capture shows moving objects, else `off`. Captures from "
         "files decide before painting (every frame compared with the frames near it through "
         "the mesh: more than 0.4 % of the pixels differing from most of them in regions, not "
         "lines along the image's edges, which blur, a pose slightly off or the mesh's error "
         "make); the app and "
         "live captures decide once warmed up (`robust` learns from the start and stays when "
         "the texels it trusts show enough foreground). The decision and its evidence are in "
         "the background stage's report and `metrics.json`");
  v.Field(
      "training_frames", o.training_frames,
      {.min = 1, .max = 250, .help = "`average`: samples averaged per texel before it segments"});
  v.Field("average_threshold", o.average_threshold,
          {.min = 0,
           .help = "`average`: foreground beyond this largest-channel difference, grey levels"});
  v.Field("warmup_frames", o.warmup_frames,
          {.min = 1,
           .help = "`robust`: samples before a texel's model is trusted (until then it paints "
                   "provisionally)"});
  v.Field("window_frames", o.window_frames,
          {.min = 2,
           .max = 65535,
           .help = "`robust`: learning window in samples: an object that stops for about half of "
                   "it becomes background"});
  v.Field("majority", o.majority,
          {.min = 0,
           .max = 1,
           .help = "`robust`: the share of a texel's recent samples its background must explain "
                   "before the model masks or trusts them (below it, they paint provisionally, "
                   "the sharpest kept)"});
  v.Field(
      "sigma_threshold", o.sigma_threshold,
      {.min = 0,
       .min_exclusive = true,
       .help = "`robust`: foreground beyond this many standard deviations of the texel's noise"});
  v.Field("min_sigma", o.min_sigma,
          {.min = 0,
           .min_exclusive = true,
           .max = 100,
           .help = "`robust`: the noise is never counted below this many grey levels"});
  v.Field("normalize_gain", o.normalize_gain,
          {.help = "`robust`: divide each frame by its global gain (exposure changes)"});
  v.Field("min_blob_texels", o.min_blob_texels,
          {.min = 0, .help = "mask cleaning: smaller foreground blobs are noise"});
  v.Field("dilate_texels", o.dilate_texels,
          {.min = 0,
           .max = 64,
           .help = "mask cleaning: the remaining foreground grows by this margin"});
  v.Enum("grow", o.grow, GrowModeNames(),
         "foreground grows from what cleaning kept into neighbouring texels of a similar "
         "colour (a mover's samples where texels learned it as background); `auto` (the "
         "default): once the refinement's `auto` has measured the frames and found them "
         "aligned (not while refinement is not `auto`, nor when it could not measure)");
  v.Field("grow_levels", o.grow_levels,
          {.min = 0,
           .max = 255,
           .help = "`grow`: a neighbour joins when every channel is within this many grey "
                   "levels of the flagged texel it grows from"});
  v.Field("grow_reach_texels", o.grow_reach_texels,
          {.min = 0, .max = 4096, .help = "`grow`: how far, in texels, the foreground may grow"});
  v.Field("across_views", o.across_views,
          {.help = "captures from files, with a background model: the pixels found before "
                   "painting to differ from most of the frames near them (compared through the "
                   "mesh: moving objects) are not painted, and join the model's foreground "
                   "where they touch it in a buffer, when it grows (`grow`; `auto`: also while "
                   "refinement is still deciding, in the first two frames and once it has "
                   "measured a frame); growth does not start from the pixels the frames near "
                   "them agree with (where a mover the model learned has gone) (on: less of the "
                   "movers painted and more of the rest; off: the model alone)"});
  v.Field("mover_margin", o.mover_margin,
          {.min = 0,
           .max = 0.25,
           .help = "`across_views`: the pixels around the movers found, out to this share of "
                   "the frame's longer side, are not painted either (a mover's edge and the "
                   "background it just uncovered, where the frames near it disagree about which "
                   "is the mover); 0: none"});
}

}  // namespace fresco
