// Runs one setting over an evaluation suite (eval_suite.h): each capture is generated into
// the cache (or found current there), painted with the project's settings plus the given
// overrides through the painting job (pipeline/run/: the whole-capture pre-pass, the paint
// run) while every `holdout`-th frame is held out, and the held-out frames are scored by the
// one held-out scorer (pipeline/rephoto/holdout_scorer.h): rephotography at the given poses,
// truth at the true poses (truth_view.h), mover leak.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/eval/eval_suite.h"
#include "pipeline/paint/stage_report.h"

namespace fresco {

inline constexpr double kNoFigure = std::numeric_limits<double>::quiet_NaN();

struct EvalOptions {
  std::vector<std::string> overrides;  // project settings "KEY=VALUE" (as `fresco run --set`)
  std::string cache_dir;               // captures are written to CACHE/NAME/
  int holdout = 10;                    // every N-th frame is held out of painting (>= 2)
  double leak_threshold = 40.0;        // levels; see TruthViewInputs::leak_threshold
  // Paint at the true poses instead of the given ones (the held-out frames are rephotographed
  // at theirs too): PaintJobOptions::paint_at_truth_poses.
  bool true_poses = false;
  // Also paint each capture as references for what refinement recovers: at the given poses
  // with refinement off, and (where the given poses are noisy) at the true poses.
  bool recovery = false;
  // Progress: (captures done, total, a line about the capture just started or finished).
  std::function<void(int done, int total, const std::string& line)> progress;
  std::function<bool()> stop;  // checked between frames; true: stop with an error
  Status Check() const;
};

// One capture's figures (means over its held-out frames).
struct CaptureEval {
  std::string name, family;
  int frames = 0, painted_frames = 0, holdout_frames = 0;
  bool generated = false;  // false: the cached capture was current
  double generate_seconds = 0;
  double paint_fps = 0;  // painted frames per second spent in PaintFrame
  double psnr_db = 0;    // rephotography at the given poses
  double one_minus_ncc = 0;
  double completeness = 0;   // surface pixels of the held-out views that are painted
  double truth_psnr_db = 0;  // at the true poses against the clean scene
  double truth_one_minus_ncc = 0;
  bool has_movers = false;
  double mover_leak = 0;  // painted pixels showing a mover / painted pixels (truth views)
  // Painted pixels off by more than the leak threshold where a mover passed / painted pixels
  // (truth views): the movers and any other error there.
  double mover_region_error = 0;
  // Texel space (MoverProvenance): painted on-surface texels whose colour came from a mover,
  // those of them seen with a mover at least as often as without, and the texels seen
  // mover-free at least once that are painted (fractions).
  double mover_texels = 0, mover_dominated_texels = 0, open_coverage = 0;
  // The texels painted from a mover by why (fractions of the painted texels; they sum to
  // mover_texels, MoverProvenance::Figures): never seen without a mover, every sample without
  // one kept out of painting, one not kept out but not taken, one painted and then replaced.
  double mover_never_open = 0, mover_open_masked = 0, mover_open_passed = 0,
         mover_open_replaced = 0;
  double coverage = 0;  // on-surface texels painted
  // background.mode auto: the share of the surface pixels judged that were found in compact
  // regions (MoverMaskResult::compact: the evidence decided on; NaN when not run).
  double movers_across_views = std::numeric_limits<double>::quiet_NaN();
  bool noisy_poses = false;  // the given poses differ from the true ones
  // refine.joint: whether the poses' joint adjustment ran and was applied, on how many frames
  // it decided, and its two ratios (the frames left out; all tracks: RMS before / after).
  bool joint_ran = false, joint_applied = false;
  int joint_decided_on_frames = 0;
  double joint_check_ratio = 0, joint_tracks_ratio = 0;
  double joint_one_end_ratio = 0;  // check_before_px / check_one_end_px
  // With EvalOptions::recovery (NaN otherwise): truth PSNR with refinement off at the given
  // poses, with the setting at the true poses (noisy captures only), and the share of the
  // PSNR lost to pose noise that the setting recovers (where at least 0.5 dB is lost).
  double unrefined_truth_psnr_db = kNoFigure;
  double true_pose_truth_psnr_db = kNoFigure;
  double recovered = kNoFigure;
  AutoDecisions decisions;  // what the `auto` modes decided, with their evidence
};

// Generates (or finds current) and evaluates one capture.
Status EvaluateCapture(const EvalSuite& suite, const SuiteCapture& capture,
                       const EvalOptions& options, CaptureEval* result);

// Every capture in order.
Status EvaluateSuite(const EvalSuite& suite, const EvalOptions& options,
                     std::vector<CaptureEval>* results);

}  // namespace fresco
