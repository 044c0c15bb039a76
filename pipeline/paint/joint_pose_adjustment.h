// Joint adjustment of a capture's camera poses against the mesh they paint (bundle
// adjustment with the scene's geometry known). Refinement frame by frame (refine_pose.h)
// registers each frame to what the buffers already hold, so its corrected poses inherit the
// pose errors of the frames that painted them first: a slowly varying bias of about the
// noise / sqrt(painters). Here every frame is matched to several others (image corners tracked
// from one frame to the next 1, 2, 4, ... frames, started where the given poses put them) and
// all poses are corrected together: the matches fix the poses relative to each other, and the
// given poses, as a weak prior on each, fix where the whole set sits (their errors average
// over the whole capture instead of over a wall's first painters).
//
// A match: frame i's pixel u_i and frame j's pixel u_j show the same surface point. With
// corrections x_i, x_j (rotation vector and translation, camera frame, applied on the left:
// corrected cam_from_local = exp(x) * given), the point is where frame i's ray through u_i
// meets the plane of the mesh triangle it hits at the given pose, and its projection in frame
// j should fall on u_j. Robust (Huber) Gauss-Newton over all corrections at once, sparse.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"

namespace fresco {

struct PoseAdjustFrame {
  cv::Mat bgr;  // CV_8UC3 (or CV_8U grey)
  const Camera* camera = nullptr;
  Rigid3d cam_from_local;  // given
};

struct PoseAdjustOptions {
  std::vector<int> offsets = {1, 2, 4, 8, 16};  // frame i is matched to i + each offset
  int max_corners = 300;                        // per frame
  double min_corner_distance_px = 10;
  double forward_backward_px = 0.5;  // a track must come back to within this
  double search_px = 20;             // a track this far from where the given poses put it: dropped
  int window_px = 15;                // tracking window (pixels, square)
  // Frames whose longer side exceeds this are tracked at half (a quarter, ...) resolution;
  // pixel figures below are then at that resolution. 0: always at full resolution.
  int max_side_px = 720;
  // The given poses' assumed error: a prior on each correction. Weaker priors let the image
  // noise move what the matches hardly see (a camera's sideways step against its turn).
  double rotation_prior_deg = 0.5;
  double translation_prior_m = 0.01;
  // Further rounds with priors from the corrections found (their RMS per axis times
  // prior_from_corrections, never below the priors above): given poses noisier than the
  // priors assume (3 cm against 1 cm) are then corrected in full. 0 rounds: the priors above.
  int prior_rounds = 2;
  double prior_from_corrections = 1.5;
  double match_sigma_px = 0.5;
  double huber_px = 1.0;
  int iterations = 6;
  // From this iteration on, each frame gap's matches are weighted by the inverse of their
  // spread at the time (0: all matches weigh the same).
  int weigh_gaps_after = 2;
  bool translation = true;  // false: rotations only
  // The check that decides whether the corrections are applied, made first: the tracks over
  // check_offsets (those of `offsets` in it) are split into those between frames of one parity
  // (even offsets) and those between the even and the odd frames (odd offsets); the even and the
  // odd frames are adjusted each from the tracks between their own frames only, and the tracks
  // between the two halves, left out of both estimates, are measured with one end at its given
  // pose and the other at its half's correction (a frame left out of the adjustment against the
  // corrected frames: what a view at a given pose sees of what the corrected frames paint; the
  // mean of both ways), against both ends at their given poses. Only when they agree
  // check_min_improvement times better (RMS) are the other tracks made and all poses adjusted
  // together from every track, the corrections applied; else the given poses stand and nothing
  // more is done. With 0.3-0.5 degree or 2-5 cm of noise the frame left out agrees sqrt(2)
  // times better (its own error is left, not the other's: 1.28-1.54 on the evaluation suite);
  // corrections fitted to the tracks' own errors (exact poses, 0.58-1.00) or to an error of
  // the mesh (the TUM teddy with motion-capture poses: 0.87 on its 110k-triangle crop, 0.84 on
  // the whole 435k-triangle mesh) make it agree worse. Both ends corrected (check_after_px),
  // the teddy's tracks agree 2.3 times better: that figure is fooled by a mesh's error.
  // 0: no check, the corrections are always applied.
  std::vector<int> check_offsets = {1, 2, 4};
  double check_min_improvement = 1.1;
  // Captures of more than 1.5 times this many frames are decided on their first this many
  // first: when those frames' adjustment is not applied (the check), the rest
  // is not tracked and the given poses stand (most of the cost saved where nothing is
  // corrected); when it is, the whole capture is adjusted and decided as above. 0: the whole
  // capture at once.
  int decide_on_first_frames = 32;
  // Those first frames (a shorter capture: all of its frames, where they are tracked smaller
  // at this size than at max_side_px) are tracked for the decision at this size (as
  // max_side_px; 0: as the whole capture): where they pass, the whole capture is tracked,
  // checked and adjusted at max_side_px.
  int decide_max_side_px = 360;
  // Captures with more frames are not adjusted (not_run says so): every frame is held in
  // memory, with its depth and triangle maps (a few MB a frame).
  int max_frames = 500;
  // Progress (optional): frames prepared, then matched, then solver iterations.
  std::function<void(int done, int total, const std::string& line)> progress;
};

struct PoseAdjustResult {
  bool applied = false;                 // false: the given poses stand (the check)
  std::string not_run;                  // why nothing was tried ("" when it ran)
  std::vector<Rigid3d> cam_from_local;  // corrected (or given), one per frame
  std::vector<int> frame_matches;       // matches each frame takes part in
  int matches = 0, inliers = 0;
  // The check (PoseAdjustOptions::check_*): the tracks between the halves, their RMS at the
  // given poses, with one end at its half's correction (what decides) and with both (pixels
  // at the check's size, each residual capped where a track counts as wrong), and what it took.
  int check_matches = 0;
  double check_before_px = 0, check_one_end_px = 0, check_after_px = 0;
  double check_seconds = 0;
  // The adjustment (when the check passes): its tracks' RMS at the given and corrected poses.
  double rms_before_px = 0, rms_after_px = 0;                // over the inliers
  double median_rotation_deg = 0, median_translation_m = 0;  // corrections found
  double rotation_prior_deg = 0, translation_prior_m = 0;    // the priors of the last round
  double seconds = 0;
  // The frames the figures above come from: all of them, or the first ones when the decision
  // on those ended it (PoseAdjustOptions::decide_on_first_frames).
  int decided_on_frames = 0;
};

// Why a capture of `frames` frames is not adjusted ("" when it is): more than max_frames.
std::string TooManyFramesToAdjust(int frames, const PoseAdjustOptions& options);

Status AdjustPosesOnMesh(const TriangleMesh& mesh, const std::vector<PoseAdjustFrame>& frames,
                         const PoseAdjustOptions& options, PoseAdjustResult* result);

}  // namespace fresco
