// Verification of given poses against an independent COLMAP reconstruction (docs/contract.md,
// `fresco poses verify`): COLMAP's poses are aligned to the given ones (pose_alignment.h),
// globally, or locally (a window of neighbouring frames) on long sequences whose
// reconstruction drifts in scale, and each frame's rotation and position disagreement is
// compared with thresholds. Pure computation: no files (verify_report.h writes them).
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/poses/pose_alignment.h"

namespace fresco {

struct VerifyOptions {
  // A frame is flagged when its rotation disagrees by more than this...
  double rotation_threshold_deg = 0.5;
  // ...or its camera centre by more than this fraction of the scene size.
  double position_threshold_rel = 0.01;
  // Local alignment: each frame is judged by a similarity fitted to the `window_frames`
  // registered frames around it (in sequence order); one global fit when the sequence has
  // no more registered frames than that. 0 = always global.
  int window_frames = 40;
  // Frames within these fractions of the thresholds support the alignment fit.
  double inlier_fraction = 0.5;
  // When the disagreement drifts smoothly along the sequence (COLMAP's reconstruction bends
  // over a long walk), each frame is judged against its neighbours' disagreement (a robust
  // line through the `drift_neighbours` frames on each side) instead of against none: a
  // frame that disagrees as its neighbours do follows the drift and is not flagged; one that
  // stands out from them is. Its rotation is also judged without any alignment: the
  // rotations between it and each neighbour, given against COLMAP's, through a robust line
  // over the neighbours' offsets (a drift that bends faster than the line through the
  // disagreements follows still moves these little). 0 = never.
  int drift_neighbours = 5;
  // A frame beyond the thresholds whose COLMAP pose rests on fewer than this fraction of the
  // median frame's observations (2D points with a 3D point; a reconstruction's last frames,
  // where it often turns away) is not judged: its pose from COLMAP is too weak to say that
  // the given one is wrong. 0 = always judged.
  double weak_support_fraction = 0.3;
  unsigned seed = 1;

  Status Check() const;
};

struct FrameVerdict {
  std::string name;
  bool has_given = false;   // the project gives a pose for it
  bool registered = false;  // COLMAP registered it
  // When both: the disagreement the verdict used. Where judged against the drift
  // (`judged_locally`), after the local alignment its neighbours give (the rotation through
  // the rotations between it and them, relative_rotation_deg; the centre against the line
  // through their offsets); else under the fit of its window.
  double rotation_error_deg = 0.0;
  double position_error_m = 0.0;
  // The same under the fit of its window alone (where a reconstruction drifts, mostly the
  // drift's).
  double fit_rotation_error_deg = 0.0;
  double fit_position_error_m = 0.0;
  bool judged_locally = false;
  bool flagged = false;
  // Where judged against the drift: how far the local alignment itself may be off (1.5
  // standard errors of it, from how its neighbours scatter about their line), and whether the
  // frame's error is within that of the threshold (neither surely beyond nor surely within:
  // not flagged, not counted as agreeing).
  double rotation_uncertainty_deg = 0.0;
  double position_uncertainty_m = 0.0;
  bool borderline = false;
  // Where judged against the drift: the drift itself (its neighbours' line where it is)
  // carries it beyond the thresholds under its window's fit.
  bool in_drift = false;
  // In the drift, within the thresholds (or a widened tolerance) after the local alignment:
  // beyond them only as its neighbours are. Not flagged.
  bool follows_drift = false;
  // Where judged against the drift: how far the frame's given rotation turns from what its
  // neighbours' given rotations and COLMAP's rotations between them imply (alignment-free;
  // < 0: not measured).
  double relative_rotation_deg = -1.0;
  // Where judged against the drift: how far it may stand out from its neighbours' line, in
  // units of the thresholds (1, or more where the neighbours scatter more; 0: not judged).
  double drift_tolerance = 0.0;
  // Where compared: the camera centres, given and COLMAP's under the alignment the frame was
  // judged by, local where judged locally (world, metres; their distance is
  // position_error_m).
  Eigen::Vector3d given_centre_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d colmap_centre_m = Eigen::Vector3d::Zero();
  int observations = -1;      // COLMAP's 2D points with a 3D point (-1: unknown)
  bool weak_support = false;  // beyond the thresholds, not judged: see weak_support_fraction
  bool inlier = false;        // supported the (global or its local) alignment
};

struct VerifyResult {
  std::vector<FrameVerdict> frames;  // in sequence order
  int registered = 0;                // frames COLMAP registered
  int compared = 0;                  // frames with both poses
  int flagged = 0;
  double scene_size_m = 0.0;
  double rotation_threshold_deg = 0.0;
  double position_threshold_m = 0.0;
  // The global alignment (all compared frames) and its support.
  Sim3d world_from_colmap;
  int global_inliers = 0;
  int windows = 1;  // distinct local fits (1 = global only)
  // The given camera centres: collinear (a straight path: the rotation comes from the
  // orientations alone) or not; and which start of the fit won (pose_alignment.h).
  CentreSpread centres;
  std::string rotation_from;
  // Frames within the flag thresholds of the global alignment; fewer than half the compared
  // ones (`weak_alignment`): COLMAP's reconstruction and the given poses disagree as a
  // whole, so single flags mean little. (Not the inliers: those shrink to 3x their own
  // median error when COLMAP is precise.)
  int global_agreeing = 0;
  bool weak_alignment = false;
  // How the frames beyond the thresholds disagree with the global alignment: smoothly along
  // the sequence (a drift, pose_alignment.h), or frame by frame.
  Disagreement disagreement;
  // Where the drift is followed: the first and last frame in it (`in_drift`: the stretch where
  // only a local alignment agrees); else the first and last smooth frame of `disagreement`.
  std::string drift_first, drift_last;
  // The frames were judged against the drift (VerifyOptions::drift_neighbours): each after
  // the local alignment its neighbours give (`judged_locally`, how many), and of the compared
  // frames `flagged` + `borderline` + `following_drift` + `weak_support` + `unflagged` =
  // `compared`.
  bool drift_followed = false;
  int judged_locally = 0;
  int following_drift = 0;
  int borderline = 0;
  double widest_rotation_uncertainty_deg = 0.0;  // of the borderline frames
  // Of the frames following the drift, those judged with a wider tolerance (their neighbours
  // scatter beyond the thresholds: a reconstruction bending unevenly), and the widest, as a
  // rotation (the tolerance times rotation_threshold_deg): a given pose wrong by less than
  // that goes unnoticed there.
  int widened = 0;
  double widest_tolerance_deg = 0.0;
  // Frames beyond the thresholds not judged for their COLMAP pose's weak support, and the
  // median observations they were measured against (VerifyOptions::weak_support_fraction).
  int weak_support = 0;
  double median_observations = 0.0;
  double weak_support_fraction = 0.0;
  // Statistics of the unflagged frames that agree within the thresholds (those following a
  // drift left out): how well COLMAP and the poses agree; zero when `unflagged` is 0.
  int unflagged = 0;
  double median_rotation_error_deg = 0.0, max_unflagged_rotation_error_deg = 0.0;
  double median_position_error_m = 0.0, max_unflagged_position_error_m = 0.0;
};

// One line each for the CLI, the report and the panel: what the numbers mean and what to
// be wary of (degenerate centres, weak alignment, no frame agreeing).
std::vector<std::string> VerifyNotes(const VerifyResult& result);
// A frame's verdict in a few words, for tables: "not registered", "no given pose", "FLAGGED
// rotation position", "follows the drift (within 2.3 deg)", "not judged: weak COLMAP pose (52
// points)", "ok" or "ok (not in fit)".
std::string VerdictText(const FrameVerdict& frame, const VerifyResult& result);
// "The 37 unflagged frames agree within ..."; with frames that are neither flagged nor
// agreeing, "Of the 118 unflagged frames, 72 agree within ..., 18 are borderline, 25 follow
// the drift and 3 were not judged." (the counts add up); with none agreeing, says so.
std::string VerifyAgreementText(const VerifyResult& result);

// One entry per frame of the sequence, in order.
struct VerifyFrameInput {
  std::string name;
  const Rigid3d* given_cam_from_world = nullptr;    // nullptr: no given pose
  const Rigid3d* colmap_cam_from_colmap = nullptr;  // nullptr: not registered
  // A keyframe: the alignment, its windows and the drift are measured on these; a frame
  // that is not one (registered to the keyframes' reconstruction afterwards) is judged by
  // the fit and the neighbours of the keyframes beside it.
  bool reference = true;
  int colmap_observations = -1;  // COLMAP's 2D points with a 3D point (-1: unknown)
};

Status VerifyPoses(const std::vector<VerifyFrameInput>& frames, double scene_size_m,
                   const VerifyOptions& options, VerifyResult* result);

}  // namespace fresco
