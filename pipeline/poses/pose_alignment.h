// Aligning a COLMAP reconstruction (arbitrary scale, rotation, translation) to the project's
// given poses, from two starts, keeping the one more frames support:
//  - orientations: each frame's own world_from_colmap rotation (world_from_cam given *
//    cam_from_colmap), the one most others agree with (1-point RANSAC), then scale and
//    translation from the centres of those frames (2-point RANSAC, rotation held);
//  - centres: a robust similarity from the camera centres (RANSAC over minimal sets,
//    similarity.h); skipped when the centres are degenerate (below).
// Each start is refined: rotation from the orientations (chordal mean of the inliers'
// rotations), scale and translation refitted with it, inliers re-selected, then once more
// with thresholds from the inliers' own spread. Outlier poses (by position or orientation)
// do not bend the fit.
//
// Degenerate centres: camera centres on (nearly) one line (a straight walk or drive) leave
// the rotation about that line free in a fit from centres alone; the orientations fix it.
// Centres that (nearly) coincide (a camera turning on the spot) leave the scale free: an
// error. Also the per-frame disagreement of a given pose with an aligned COLMAP pose.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"
#include "pipeline/poses/similarity.h"

namespace fresco {

// One frame with both a given pose and a COLMAP pose.
struct PosePair {
  std::string name;
  Rigid3d given_cam_from_world;
  Rigid3d colmap_cam_from_colmap;
};

struct PoseAlignmentOptions {
  // A frame supports the fit when its aligned camera centre is within this of the given one
  // (metres) and its orientation within `inlier_rotation_deg`.
  double inlier_position_m = 0.05;
  double inlier_rotation_deg = 0.5;
  int iterations = 500;  // RANSAC trials
  unsigned seed = 1;
  // After the fit (with >= 6 inliers), the thresholds shrink to this many times the
  // inliers' median errors (but not below 5 % of the thresholds above) and the fit is
  // redone: poses a little off stop bending it. 0 = off.
  double adaptive_factor = 3.0;
  // The given camera centres are called collinear when the second singular value of the
  // centred centres is below this fraction of the first, and coincident when their RMS
  // distance from their mean is below `inlier_position_m`.
  double collinear_ratio = 0.05;

  Status Check() const;
};

// The shape of the given camera centres.
struct CentreSpread {
  double spread_ratio = 0.0;  // second / first singular value of the centred centres
  double rms_m = 0.0;         // RMS distance of the centres from their mean
  bool collinear = false;     // (nearly) on one line: see PoseAlignmentOptions
  bool coincident = false;    // (nearly) one point
  bool Degenerate() const { return collinear || coincident; }
};
CentreSpread MeasureCentreSpread(const std::vector<Eigen::Vector3d>& centres,
                                 const PoseAlignmentOptions& options);

struct PoseAlignment {
  Sim3d world_from_colmap;
  std::vector<bool> inliers;  // per pair
  int num_inliers = 0;
  CentreSpread centres;  // of the given poses
  // Which start won: "orientations" or "centres" (see above).
  std::string rotation_from;
};

// Needs >= 3 pairs whose given camera centres do not coincide, and >= 3 that agree.
Status AlignColmapToPoses(const std::vector<PosePair>& pairs, const PoseAlignmentOptions& options,
                          PoseAlignment* alignment);

// Disagreement of the given pose with the COLMAP pose brought into the world.
struct PoseError {
  double rotation_deg = 0.0;
  double position_m = 0.0;  // distance between camera centres
};
PoseError ComparePose(const PosePair& pair, const Sim3d& world_from_colmap);

// How the frames beyond the thresholds disagree, in sequence order (`pairs` in order): a
// frame's disagreement is its rotation (world side, in units of `rotation_deg`) and centre
// offset (in units of `position_m`) from the given pose to the aligned COLMAP pose. It is
// smooth where a neighbour also disagrees and differs from it by under half its size, or
// where the median of the 3 frames on each side does: one of the two (COLMAP's
// reconstruction or the given poses) drifts along the sequence, which a wrong given pose
// here and there does not do.
struct Disagreement {
  int disagreeing = 0;        // frames beyond either threshold
  int smooth = 0;             // of those, the smooth ones
  int first = -1, last = -1;  // pair indices of the first and last smooth frame
  bool Drifts() const { return smooth >= 3 && 2 * smooth >= disagreeing; }
};
// One frame's disagreement: the rotation (world side, as a rotation vector in units of
// `rotation_deg`) and centre offset (in units of `position_m`) from the given pose to the
// aligned COLMAP pose.
Eigen::Matrix<double, 6, 1> DisagreementOf(const PosePair& pair, const Sim3d& world_from_colmap,
                                           double rotation_deg, double position_m);
Disagreement MeasureDisagreement(const std::vector<PosePair>& pairs, const Sim3d& world_from_colmap,
                                 double rotation_deg, double position_m);

// The median of `values` (the upper one of an even count); 0 when empty.
double Median(std::vector<double> values);

}  // namespace fresco
