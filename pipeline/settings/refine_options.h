// The refinement stage's settings: the struct the stage reads, and its fields as the project
// file, `--set`, `fresco settings`, the app's settings widgets and the docs' settings table
// see them (each with its range and help, listed once in Fields). Adding a setting is a member
// here and its line in Fields; nothing else.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "pipeline/settings/setting_rule.h"

namespace fresco {

// Texture alignment refinement (paper §3.5, refine_alignment.h). kAuto: measures the
// misalignment between the first frames and the buffers without correcting, then refines
// (`robust`) for the rest of the capture only when a pose correction would remove enough of
// it (auto_modes.h).
enum class RefineMode { kOff, kPaper, kRobust, kAuto };
// The most general 2D motion model refinement may choose (model selection picks simpler
// ones when the evidence does not need more).
enum class RefineModelLimit { kTranslation, kSimilarity, kAffine, kHomography };
struct RefineOptions {
  RefineMode mode = RefineMode::kAuto;
  RefineModelLimit max_model = RefineModelLimit::kHomography;
  int max_corners = 150;           // corners tracked per buffer and frame
  int search_px = 12;              // largest correction looked for, texels (else: no correction)
  int window_px = 7;               // matching window half-size, texels
  int pyramid_levels = 3;          // coarse-to-fine levels (robust mode)
  double ransac_px = 1.5;          // inlier threshold, texels
  double max_scale_change = 0.05;  // a fit that scales or shears more is refused
  // Corrections smaller than this (largest displacement over the region, texels) are
  // measured but not applied: registration noise applied frame after frame random-walks
  // the buffer away from the model.
  double min_correction_px = 0.25;
  int min_inliers = 10;
  // Register every Nth frame only (1 = every frame); the others only fill texels the
  // buffers lack (unregistered, they would overwrite registered texels with their error).
  int every_n_frames = 1;
  // Consensus anchoring (refine_anchor.h): move a buffer back by the mean of the corrections
  // it asked for, once anchor_min_frames agree on a move larger than anchor_step_px texels.
  bool anchor = true;
  // Correct the frame's pose from the matches of every buffer together, and derive each
  // buffer's correction from it (refine_pose.h), instead of one homography per buffer.
  bool pose = true;
  // Before painting, correct all the given poses together against the mesh (captures read
  // from files only; joint_pose_adjustment.h). A check on frames left out of the estimate
  // (PoseAdjustOptions::check_min_improvement) decides whether the corrections are used.
  bool joint = true;
  int anchor_min_frames = 3;
  int anchor_window_frames = 100;  // samples fade with this time constant (0: never)
  double anchor_step_px = 0.1;

  bool operator==(const RefineOptions&) const = default;
};

inline const EnumNames<RefineMode>& RefineModeNames() {
  static const EnumNames<RefineMode> names = {
      {RefineMode::kOff, "off"},
      {RefineMode::kPaper, "paper"},
      {RefineMode::kRobust, "robust"},
      {RefineMode::kAuto, "auto"},
  };
  return names;
}

inline const EnumNames<RefineModelLimit>& RefineModelNames() {
  static const EnumNames<RefineModelLimit> names = {
      {RefineModelLimit::kTranslation, "translation"},
      {RefineModelLimit::kSimilarity, "similarity"},
      {RefineModelLimit::kAffine, "affine"},
      {RefineModelLimit::kHomography, "homography"},
  };
  return names;
}

template <class V>
void Fields(RefineOptions& o, V& v) {
  v.Enum("mode", o.mode, RefineModeNames(),
         "`paper`: Harris corners, SSD search, affine fit (the paper's §3.5); `robust`: tracked "
         "corners, RANSAC and model selection; `auto` (the default): the first frames' "
         "misalignment to the buffers is measured without correcting, and `robust` refines the "
         "rest of the capture only when the part of it a pose correction would remove exceeds "
         "0.25 texels (median; perfect poses give 0-0.02, with movers and distortion too) and, "
         "where the joint pose adjustment ran, its check passed (frames left out of its "
         "corrections agree 1.1 times better with the corrected frames: else a mesh's error, "
         "not the poses', is what looks misaligned); the decision and its evidence are in the "
         "refine stage's report");
  v.Enum("max_model", o.max_model, RefineModelNames(),
         "the most general 2D motion `robust` may choose (simpler ones win when the evidence does "
         "not need more)");
  v.Field("max_corners", o.max_corners, {.min = 3, .help = "corners tracked per buffer and frame"});
  v.Field("search_px", o.search_px,
          {.min = 1, .help = "largest correction looked for, texels (larger: no correction)"});
  v.Field("window_px", o.window_px,
          {.min = 1, .max = 64, .help = "matching window half-size, texels"});
  v.Field("pyramid_levels", o.pyramid_levels,
          {.min = 0, .max = 8, .help = "coarse-to-fine levels (`robust`)"});
  v.Field("ransac_px", o.ransac_px,
          {.min = 0, .min_exclusive = true, .help = "inlier threshold, texels"});
  v.Field("max_scale_change", o.max_scale_change,
          {.min = 0,
           .min_exclusive = true,
           .max = 1,
           .help = "a fit that scales or shears more is refused"});
  v.Field("min_inliers", o.min_inliers, {.min = 3, .help = "fewer inliers: no correction"});
  v.Field("min_correction_px", o.min_correction_px,
          {.min = 0, .help = "dead band: smaller corrections are measured but not applied"});
  v.Field("every_n_frames", o.every_n_frames,
          {.min = 1,
           .help = "register every N-th frame; the others only fill texels the buffers lack"});
  v.Field("anchor", o.anchor,
          {.help = "consensus anchoring: move a buffer back by the mean of the corrections the "
                   "frames ask for"});
  v.Field("pose", o.pose,
          {.help = "correct the frame's camera pose from the matches of all its buffers together, "
                   "instead of one homography per buffer"});
  v.Field("joint", o.joint,
          {.help = "before painting, correct all the given poses together: image corners tracked "
                   "from each frame to the next 1, 2, 4, 8 and 16 frames through the mesh, one "
                   "adjustment of every pose (`fresco run`, `bench`, `rephoto` and `eval` on "
                   "captures from files; live captures and the app's frame-by-frame painting "
                   "ignore it); "
                   "first a check: the even and the odd frames are adjusted apart, and only when "
                   "the tracks between them, which neither saw, agree 1.1 times better with one "
                   "frame of each at its given pose and the other corrected (a view at a given "
                   "pose against what the corrected frames paint) are all the poses adjusted "
                   "and the corrections used (exact poses, or poses fitted to an error of the "
                   "mesh, stay as given and cost the check only); on by default"});
  v.Field("anchor_min_frames", o.anchor_min_frames,
          {.min = 2, .help = "frames that must agree before a buffer is moved"});
  v.Field("anchor_window_frames", o.anchor_window_frames,
          {.min = 0, .help = "anchor samples fade with this time constant, frames (0 = never)"});
  v.Field("anchor_step_px", o.anchor_step_px,
          {.min = 0, .help = "a buffer is moved when the agreed offset exceeds this, texels"});
}

}  // namespace fresco
