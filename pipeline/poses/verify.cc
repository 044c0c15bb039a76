#include "pipeline/poses/verify.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace fresco {

Status VerifyOptions::Check() const {
  if (!(rotation_threshold_deg > 0)) return Status::Error("rotation_threshold_deg: must be > 0");
  if (!(position_threshold_rel > 0)) return Status::Error("position_threshold_rel: must be > 0");
  if (window_frames < 0) return Status::Error("window_frames: must be >= 0");
  if (drift_neighbours < 0) return Status::Error("drift_neighbours: must be >= 0");
  if (window_frames > 0 && window_frames < 5) {
    return Status::Error("window_frames: must be 0 or >= 5");
  }
  if (!(weak_support_fraction >= 0 && weak_support_fraction < 1)) {
    return Status::Error("weak_support_fraction: must be in [0, 1)");
  }
  if (!(inlier_fraction > 0 && inlier_fraction <= 1)) {
    return Status::Error("inlier_fraction: must be in (0, 1]");
  }
  return Status::Ok();
}

namespace {

// The robust line (Theil-Sen: the median slope, then the median intercept) through (x, y).
struct RobustLine {
  double slope = 0.0, at_zero = 0.0;
  double At(double x) const { return at_zero + slope * x; }
};
RobustLine TheilSen(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<double> slopes, at_zero;
  for (size_t a = 0; a < x.size(); ++a)
    for (size_t b = a + 1; b < x.size(); ++b)
      if (x[b] != x[a]) slopes.push_back((y[b] - y[a]) / (x[b] - x[a]));
  RobustLine line;
  line.slope = slopes.empty() ? 0.0 : Median(slopes);
  for (size_t a = 0; a < x.size(); ++a) at_zero.push_back(y[a] - line.slope * x[a]);
  line.at_zero = Median(at_zero);
  return line;
}
double TheilSenAtZero(const std::vector<double>& x, const std::vector<double>& y) {
  return TheilSen(x, y).at_zero;
}

// Pair k's given rotation against its neighbours' (the pairs `around`, at `offsets` from k),
// measured by COLMAP's rotations between the same frames: no alignment, so a reconstruction
// that turns along the walk moves it only by how much it turns between neighbours, which the
// line over the offsets takes out. Degrees.
double RelativeRotationDeg(const PosePair& self, const std::vector<PosePair>& pairs,
                           const std::vector<int>& around, const std::vector<double>& offsets) {
  std::vector<double> components[3];
  for (int j : around) {
    const Eigen::Quaterniond given =
        self.given_cam_from_world.rotation * pairs[j].given_cam_from_world.rotation.conjugate();
    const Eigen::Quaterniond colmap =
        self.colmap_cam_from_colmap.rotation * pairs[j].colmap_cam_from_colmap.rotation.conjugate();
    const Eigen::Vector3d e = Rigid3d::AxisAngleFromQuaternion(colmap * given.conjugate());
    for (int c = 0; c < 3; ++c) components[c].push_back(e[c]);
  }
  Eigen::Vector3d at_k;
  for (int c = 0; c < 3; ++c) at_k[c] = TheilSenAtZero(offsets, components[c]);
  return at_k.norm() * 180.0 / M_PI;
}

// Judges frame `self` (its disagreement under its window's fit `own`) after the local
// alignment the frames `around` it (at `offsets` from it) give: a robust line through their
// disagreements (Theil-Sen per component) says how the reconstruction drifts there, and the
// frame's own is measured from it; its rotation through the rotations between it and them
// (alignment-free, relative_rotation_deg), which a reconstruction that bends faster than a
// line still moves little. These are the errors shown (`v`), with COLMAP's centre under the
// local alignment. Where the neighbours themselves scatter about their line by more than the
// thresholds, in rotation or position (a reconstruction that bends faster and faster, degrees
// a frame), the tolerance (in units of the thresholds) widens by kDriftScatter times the excess
// of their median distance from it: a frame stands out only from what its neighbours do.
// Neighbours within the thresholds (given poses with noise below them) leave it at 1.
constexpr double kDriftScatter = 3.0;
// The band about the thresholds where a frame is borderline: this many standard errors of the
// local alignment (the neighbours' median scatter about their line over the root of their
// number) either side. On a street walk's reconstruction bending by 2.8 degrees, against
// given poses with 0.3 degrees of noise (tests/poses/data/street-bend), the angle shown is
// within 1.5 of them of the truth for 103 of the 120 frames; with none, 4 frames 0.35-0.50
// degrees from the truth were flagged and one 0.52 off agreed.
constexpr double kBandWidth = 1.5;
double DriftTolerance(const std::vector<double>& scatter) {
  return 1.0 + kDriftScatter * std::max(0.0, Median(scatter) - 1.0);
}
void JudgeLocally(const PosePair& self, const Eigen::Matrix<double, 6, 1>& own,
                  const std::vector<PosePair>& pairs,
                  const std::vector<Eigen::Matrix<double, 6, 1>>& disagreement,
                  const std::vector<int>& around, const std::vector<double>& offsets,
                  const VerifyResult& out, FrameVerdict* v) {
  RobustLine lines[6];
  for (int c = 0; c < 6; ++c) {
    std::vector<double> values;
    for (int j : around) values.push_back(disagreement[j][c]);
    lines[c] = TheilSen(offsets, values);
  }
  std::vector<double> scatter_rotation, scatter_position;
  for (size_t a = 0; a < around.size(); ++a) {
    Eigen::Matrix<double, 6, 1> off;
    for (int c = 0; c < 6; ++c) off[c] = disagreement[around[a]][c] - lines[c].At(offsets[a]);
    scatter_rotation.push_back(off.head<3>().norm());
    scatter_position.push_back(off.tail<3>().norm());
  }
  const double tolerance =
      std::max(DriftTolerance(scatter_rotation), DriftTolerance(scatter_position));
  Eigen::Matrix<double, 6, 1> residual;
  for (int c = 0; c < 6; ++c) residual[c] = own[c] - lines[c].at_zero;
  const double threshold_deg = out.rotation_threshold_deg;
  // Three alignments near the frame: its window's fit, that fit corrected by the line through
  // the neighbours' disagreement, and (rotation only) the rotations between it and its
  // neighbours. The one it agrees with best gives its error: where the drift has a kink, a
  // line through the neighbours fails there, and where it bends fast, the window's fit.
  v->relative_rotation_deg = RelativeRotationDeg(self, pairs, around, offsets);
  const double rotation_deg = std::min({v->fit_rotation_error_deg, v->relative_rotation_deg,
                                        residual.head<3>().norm() * threshold_deg});
  const double threshold_m = out.position_threshold_m;
  v->judged_locally = true;
  v->drift_tolerance = tolerance;
  v->rotation_error_deg = rotation_deg;
  if (residual.tail<3>().norm() * threshold_m < v->fit_position_error_m) {
    v->position_error_m = residual.tail<3>().norm() * threshold_m;
    v->colmap_centre_m = v->given_centre_m + residual.tail<3>() * threshold_m;
  }
  // How far off the local alignment itself may be: its neighbours' median scatter about their
  // line, over the root of their number (kBandWidth such standard errors either side).
  const double root = std::sqrt(static_cast<double>(around.size()));
  v->rotation_uncertainty_deg = kBandWidth * Median(scatter_rotation) * threshold_deg / root;
  v->position_uncertainty_m = kBandWidth * Median(scatter_position) * threshold_m / root;
  const double rotation_limit = tolerance * threshold_deg;
  const double position_limit = tolerance * threshold_m;
  const bool beyond = rotation_deg > rotation_limit || v->position_error_m > position_limit;
  const bool surely_beyond = rotation_deg - v->rotation_uncertainty_deg > rotation_limit ||
                             v->position_error_m - v->position_uncertainty_m > position_limit;
  const bool surely_within = rotation_deg + v->rotation_uncertainty_deg <= rotation_limit &&
                             v->position_error_m + v->position_uncertainty_m <= position_limit;
  v->flagged = surely_beyond;
  v->borderline = !surely_beyond && (beyond || !surely_within);
  // The drift itself (the neighbours' line where the frame is), not the frame's own error,
  // carries it beyond the thresholds under its window's fit.
  const Eigen::Matrix<double, 6, 1> drift = own - residual;
  v->in_drift = drift.head<3>().norm() > 1.0 || drift.tail<3>().norm() > 1.0;
  v->follows_drift = !v->flagged && !v->borderline && v->in_drift;
}

void SetCentres(const PosePair& pair, const Sim3d& world_from_colmap, FrameVerdict* v) {
  v->given_centre_m = pair.given_cam_from_world.Centre();
  v->colmap_centre_m = world_from_colmap.TransformPose(pair.colmap_cam_from_colmap).Centre();
}

// Sets a frame's errors and centres under `fit` and flags it beyond the thresholds.
void Judge(const PosePair& pair, const PoseAlignment& fit, const VerifyResult& out,
           FrameVerdict* v) {
  const PoseError e = ComparePose(pair, fit.world_from_colmap);
  v->rotation_error_deg = v->fit_rotation_error_deg = e.rotation_deg;
  v->position_error_m = v->fit_position_error_m = e.position_m;
  SetCentres(pair, fit.world_from_colmap, v);
  v->flagged =
      e.rotation_deg > out.rotation_threshold_deg || e.position_m > out.position_threshold_m;
}

// The frames' pose pairs where both poses are known: the keyframes' (reference frames) and
// the other frames', with each one's frame index.
struct FramePairs {
  std::vector<PosePair> pairs, others;
  std::vector<int> frame_of_pair, frame_of_other;
  std::vector<int> keyframes_before_other;  // per other frame: the keyframes before it
};

// A verdict per frame (name, which poses it has) in `out`, and its pose pairs.
FramePairs CollectPairs(const std::vector<VerifyFrameInput>& frames, VerifyResult* out) {
  FramePairs split;
  for (size_t i = 0; i < frames.size(); ++i) {
    FrameVerdict v;
    v.name = frames[i].name;
    v.has_given = frames[i].given_cam_from_world != nullptr;
    v.registered = frames[i].colmap_cam_from_colmap != nullptr;
    if (v.registered) ++out->registered;
    if (v.has_given && v.registered) {
      const PosePair pair{v.name, *frames[i].given_cam_from_world,
                          *frames[i].colmap_cam_from_colmap};
      if (frames[i].reference) {
        split.pairs.push_back(pair);
        split.frame_of_pair.push_back(static_cast<int>(i));
      } else {
        split.others.push_back(pair);
        split.frame_of_other.push_back(static_cast<int>(i));
        split.keyframes_before_other.push_back(static_cast<int>(split.pairs.size()));
      }
    }
    out->frames.push_back(v);
  }
  out->compared = static_cast<int>(split.pairs.size() + split.others.size());
  return split;
}

// The global alignment of all keyframes, how many agree under it and how they disagree.
Status AlignGlobally(const std::vector<PosePair>& pairs, const PoseAlignmentOptions& align,
                     PoseAlignment* global, VerifyResult* out) {
  FRESCO_RETURN_IF_ERROR(
      AlignColmapToPoses(pairs, align, global).Reclassified(StatusKind::kFailed));
  out->world_from_colmap = global->world_from_colmap;
  out->global_inliers = global->num_inliers;
  out->centres = global->centres;
  out->rotation_from = global->rotation_from;
  for (const PosePair& pair : pairs) {
    const PoseError e = ComparePose(pair, global->world_from_colmap);
    if (e.rotation_deg <= out->rotation_threshold_deg &&
        e.position_m <= out->position_threshold_m) {
      ++out->global_agreeing;
    }
  }
  out->weak_alignment = 2 * out->global_agreeing < static_cast<int>(pairs.size());
  out->disagreement = MeasureDisagreement(pairs, global->world_from_colmap,
                                          out->rotation_threshold_deg, out->position_threshold_m);
  if (out->disagreement.Drifts()) {
    out->drift_first = pairs[out->disagreement.first].name;
    out->drift_last = pairs[out->disagreement.last].name;
  }
  return Status::Ok();
}

// The keyframes' fits: one per window of window_frames keyframes (the global one when
// windows are off or the capture is shorter), each keyframe's window and its disagreement
// under its own fit.
struct KeyframeFits {
  std::map<int, PoseAlignment> fits;                      // by window start
  std::vector<int> window_of;                             // each keyframe's window start
  std::vector<Eigen::Matrix<double, 6, 1>> disagreement;  // under each keyframe's own fit
};

// Judges each keyframe by the fit of the window around it.
KeyframeFits JudgeKeyframes(const FramePairs& split, const PoseAlignment& global,
                            const PoseAlignmentOptions& align, const VerifyOptions& options,
                            VerifyResult* out) {
  const std::vector<PosePair>& pairs = split.pairs;
  const int n = static_cast<int>(pairs.size());
  const bool local = options.window_frames > 0 && n > options.window_frames;
  KeyframeFits keyframes;
  std::map<int, PoseAlignment>& fits = keyframes.fits;
  keyframes.window_of.assign(n, 0);
  keyframes.disagreement.resize(n);
  for (int k = 0; k < n; ++k) {
    int begin = 0, end = n;
    if (local) {
      begin = std::clamp(k - options.window_frames / 2, 0, n - options.window_frames);
      end = begin + options.window_frames;
    }
    if (!fits.count(begin)) {
      if (!local) {
        fits[begin] = global;
      } else {
        const std::vector<PosePair> window(pairs.begin() + begin, pairs.begin() + end);
        PoseAlignment fit;
        // A window whose centres are degenerate (a camera standing still) uses the global fit.
        if (!AlignColmapToPoses(window, align, &fit).ok()) {
          fit = global;
          fit.inliers.assign(global.inliers.begin() + begin, global.inliers.begin() + end);
        }
        fits[begin] = fit;
      }
    }
    keyframes.window_of[k] = begin;
    const PoseAlignment& fit = fits[begin];
    FrameVerdict& v = out->frames[split.frame_of_pair[k]];
    Judge(pairs[k], fit, *out, &v);
    v.inlier = fit.inliers[k - begin];
    keyframes.disagreement[k] = DisagreementOf(
        pairs[k], fit.world_from_colmap, out->rotation_threshold_deg, out->position_threshold_m);
  }
  out->windows = static_cast<int>(fits.size());
  return keyframes;
}

// Each keyframe judged against its neighbours' disagreement (the frame itself left out), a
// robust line through them per component (Theil-Sen: the median slope, then the median
// intercept; exact on a steady drift, even at the sequence's ends): a drift is smooth, a
// wrong given pose stands out from its neighbours.
void FollowDriftOnKeyframes(const FramePairs& split, const KeyframeFits& keyframes,
                            const VerifyOptions& options, VerifyResult* out) {
  const int n = static_cast<int>(split.pairs.size());
  const int h = options.drift_neighbours;
  for (int k = 0; k < n; ++k) {
    FrameVerdict& v = out->frames[split.frame_of_pair[k]];
    std::vector<int> around;
    // 2h neighbours, also at the sequence's ends (the window shifted inwards: a line
    // extrapolated from h frames on one side is too unsure).
    const int first = std::clamp(k - h, 0, std::max(0, n - 1 - 2 * h));
    for (int j = first; j <= std::min(n - 1, first + 2 * h); ++j)
      if (j != k) around.push_back(j);
    if (static_cast<int>(around.size()) < std::min(h, n - 1)) continue;
    std::vector<double> offsets;
    for (int j : around) offsets.push_back(j - k);
    JudgeLocally(split.pairs[k], keyframes.disagreement[k], split.pairs, keyframes.disagreement,
                 around, offsets, *out, &v);
  }
}

// Other frame o (between keyframes after-1 and after), judged under `fit` against the
// keyframes around it (at their offsets from where it sits between its two).
void JudgeOtherLocally(const FramePairs& split, const KeyframeFits& keyframes, size_t o,
                       const PoseAlignment& fit, const VerifyOptions& options, VerifyResult* out) {
  const int n = static_cast<int>(split.pairs.size());
  const int after = split.keyframes_before_other[o];
  FrameVerdict& v = out->frames[split.frame_of_other[o]];
  const int h = options.drift_neighbours;
  std::vector<int> around;
  const int first = std::clamp(after - h, 0, std::max(0, n - 2 * h));
  for (int j = first; j < std::min(n, first + 2 * h); ++j) around.push_back(j);
  if (static_cast<int>(around.size()) < std::min(h, n)) return;
  // Where it sits between keyframes after-1 and after (0.5 before the first or after the last).
  double between = 0.5;
  if (after > 0 && after < n) {
    between = static_cast<double>(split.frame_of_other[o] - split.frame_of_pair[after - 1]) /
              (split.frame_of_pair[after] - split.frame_of_pair[after - 1]);
  }
  std::vector<double> offsets;
  for (int j : around) offsets.push_back(j - (after - 1 + between));
  const Eigen::Matrix<double, 6, 1> own =
      DisagreementOf(split.others[o], fit.world_from_colmap, out->rotation_threshold_deg,
                     out->position_threshold_m);
  JudgeLocally(split.others[o], own, split.pairs, keyframes.disagreement, around, offsets, *out,
               &v);
}

// The other frames (between keyframes), each by the fit of the keyframe after it (or the
// last) and, where the disagreement drifts, against the keyframes around it.
void JudgeOthers(const FramePairs& split, const KeyframeFits& keyframes,
                 const VerifyOptions& options, VerifyResult* out) {
  const int n = static_cast<int>(split.pairs.size());
  for (size_t o = 0; o < split.others.size() && n > 0; ++o) {
    const int after = split.keyframes_before_other[o];
    const PoseAlignment& fit = keyframes.fits.at(keyframes.window_of[std::min(after, n - 1)]);
    FrameVerdict& v = out->frames[split.frame_of_other[o]];
    Judge(split.others[o], fit, *out, &v);
    if (out->drift_followed) JudgeOtherLocally(split, keyframes, o, fit, options, out);
  }
}

// Flags where COLMAP's own pose rests on few points are not given.
void ExcuseWeakSupport(const std::vector<VerifyFrameInput>& frames, const VerifyOptions& options,
                       VerifyResult* out) {
  std::vector<double> observations;
  for (size_t i = 0; i < frames.size(); ++i) {
    out->frames[i].observations = frames[i].colmap_observations;
    if (out->frames[i].registered && frames[i].colmap_observations >= 0)
      observations.push_back(frames[i].colmap_observations);
  }
  out->median_observations = Median(observations);
  out->weak_support_fraction = options.weak_support_fraction;
  for (FrameVerdict& v : out->frames) {
    if (!(v.flagged || v.borderline) || v.observations < 0 ||
        v.observations >= options.weak_support_fraction * out->median_observations)
      continue;
    v.flagged = v.borderline = false;
    v.weak_support = true;
    ++out->weak_support;
  }
}

// The counts of flagged, following, weak and agreeing frames (they add up to the compared
// ones), the stretch following the drift, and the agreeing frames' error statistics.
void CountVerdicts(VerifyResult* out) {
  std::vector<double> rotations, positions;
  if (out->drift_followed) out->drift_first = out->drift_last = "";
  for (const FrameVerdict& v : out->frames) {
    if (!v.has_given || !v.registered) continue;
    out->judged_locally += v.judged_locally;
    if (v.flagged) {
      ++out->flagged;
      continue;
    }
    if (v.in_drift) {
      if (out->drift_first.empty()) out->drift_first = v.name;
      out->drift_last = v.name;
    }
    if (v.weak_support) continue;  // beyond the thresholds: not agreeing, not flagged
    if (v.borderline) {
      ++out->borderline;
      out->widest_rotation_uncertainty_deg =
          std::max(out->widest_rotation_uncertainty_deg, v.rotation_uncertainty_deg);
      continue;
    }
    if (v.follows_drift) {
      ++out->following_drift;
      if (v.drift_tolerance > 1.0 && (v.rotation_error_deg > out->rotation_threshold_deg ||
                                      v.position_error_m > out->position_threshold_m)) {
        ++out->widened;
        out->widest_tolerance_deg =
            std::max(out->widest_tolerance_deg, v.drift_tolerance * out->rotation_threshold_deg);
      }
      continue;
    }
    ++out->unflagged;
    rotations.push_back(v.rotation_error_deg);
    positions.push_back(v.position_error_m);
    out->max_unflagged_rotation_error_deg =
        std::max(out->max_unflagged_rotation_error_deg, v.rotation_error_deg);
    out->max_unflagged_position_error_m =
        std::max(out->max_unflagged_position_error_m, v.position_error_m);
  }
  out->median_rotation_error_deg = Median(rotations);
  out->median_position_error_m = Median(positions);
}

}  // namespace

Status VerifyPoses(const std::vector<VerifyFrameInput>& frames, double scene_size_m,
                   const VerifyOptions& options, VerifyResult* result) {
  // Options are checked by the callers first (bad input there): here they are a broken
  // invariant; an alignment that fails is failed work.
  FRESCO_RETURN_IF_ERROR(options.Check().Reclassified(StatusKind::kInternal));
  if (!(scene_size_m > 0)) return Status::Internal("scene size: must be > 0");
  VerifyResult out;
  out.scene_size_m = scene_size_m;
  out.rotation_threshold_deg = options.rotation_threshold_deg;
  out.position_threshold_m = options.position_threshold_rel * scene_size_m;
  const FramePairs split = CollectPairs(frames, &out);

  PoseAlignmentOptions align;
  align.inlier_position_m = options.inlier_fraction * out.position_threshold_m;
  align.inlier_rotation_deg = options.inlier_fraction * options.rotation_threshold_deg;
  align.seed = options.seed;
  PoseAlignment global;
  FRESCO_RETURN_IF_ERROR(AlignGlobally(split.pairs, align, &global, &out));

  const KeyframeFits keyframes = JudgeKeyframes(split, global, align, options, &out);
  if (options.drift_neighbours > 0 && out.disagreement.Drifts()) {
    out.drift_followed = true;
    FollowDriftOnKeyframes(split, keyframes, options, &out);
  }
  JudgeOthers(split, keyframes, options, &out);
  ExcuseWeakSupport(frames, options, &out);
  CountVerdicts(&out);
  *result = std::move(out);
  return Status::Ok();
}

std::vector<std::string> VerifyNotes(const VerifyResult& result) {
  std::vector<std::string> notes;
  char text[700];
  if (result.centres.collinear) {
    std::snprintf(text, sizeof(text),
                  "The camera centres lie nearly on one line (spread ratio %.3g): they leave the "
                  "rotation about that line free, so the alignment takes its rotation from the "
                  "camera orientations.",
                  result.centres.spread_ratio);
    notes.push_back(text);
  }
  if (result.weak_alignment) {
    std::snprintf(text, sizeof(text),
                  "Only %d of %d frames agree with the alignment: COLMAP's reconstruction and the "
                  "given poses disagree as a whole, so the flags say little about single frames "
                  "(check the reconstruction: one that drifts along the sequence, too few matches, "
                  "a broken model).",
                  result.global_agreeing, result.compared);
    notes.push_back(text);
  }
  if (result.drift_followed) {
    // The counts add up to the compared frames.
    std::string note = "The disagreement drifts smoothly along the sequence";
    if (!result.drift_first.empty()) {
      note += " from " + result.drift_first + " to " + result.drift_last;
    }
    std::snprintf(text, sizeof(text),
                  ": COLMAP's reconstruction or the given poses drift there. Each frame was "
                  "judged after aligning it to its neighbours (the angles shown are after that "
                  "alignment): of the %d compared, %d agree, %d follow the drift (beyond the "
                  "thresholds only under one fit for their window, or within the spread of "
                  "their neighbours), %d stand out (flagged), %d are borderline (within the "
                  "local alignment's own uncertainty, up to %.2g deg, of the threshold)",
                  result.compared, result.unflagged, result.following_drift, result.flagged,
                  result.borderline, result.widest_rotation_uncertainty_deg);
    note += text;
    if (result.weak_support > 0) {
      std::snprintf(text, sizeof(text), " and %d were not judged (weak COLMAP pose)",
                    result.weak_support);
      note += text;
    }
    note += ".";
    if (result.widened > 0) {
      std::snprintf(text, sizeof(text),
                    " Where the neighbours themselves scatter beyond the thresholds (a "
                    "reconstruction bending unevenly), %d frames were judged only to within "
                    "%.2g deg.",
                    result.widened, result.widest_tolerance_deg);
      note += text;
    }
    notes.push_back(note);
  } else if (result.disagreement.Drifts()) {
    std::snprintf(text, sizeof(text),
                  "%d of the %d frames beyond the thresholds disagree smoothly along the "
                  "sequence (%s to %s): COLMAP's reconstruction or the given poses drift there, "
                  "and flags in that stretch may be the reconstruction's.",
                  result.disagreement.smooth, result.disagreement.disagreeing,
                  result.drift_first.c_str(), result.drift_last.c_str());
    notes.push_back(text);
  }
  if (result.weak_support > 0) {
    std::snprintf(text, sizeof(text),
                  "%d frames beyond the thresholds were not judged: COLMAP's pose of each rests "
                  "on under %.0f%% of the median frame's %.0f observed points (often a "
                  "reconstruction's last frames, where it turns away), too weak to say the given "
                  "pose is wrong (`weak_support` in verify.json).",
                  result.weak_support, 100 * result.weak_support_fraction,
                  result.median_observations);
    notes.push_back(text);
  }
  return notes;
}

std::string VerdictText(const FrameVerdict& f, const VerifyResult& result) {
  if (!f.registered) return "not registered";
  if (!f.has_given) return "no given pose";
  char text[120];
  if (f.flagged) {
    std::snprintf(text, sizeof(text), "FLAGGED%s%s",
                  f.rotation_error_deg > result.rotation_threshold_deg ? " rotation" : "",
                  f.position_error_m > result.position_threshold_m ? " position" : "");
    return text;
  }
  if (f.borderline) {
    std::snprintf(text, sizeof(text), "borderline (%.2f +- %.2f deg)", f.rotation_error_deg,
                  f.rotation_uncertainty_deg);
    return text;
  }
  if (f.weak_support) {
    std::snprintf(text, sizeof(text), "not judged: weak COLMAP pose (%d points)", f.observations);
    return text;
  }
  if (f.follows_drift) {
    std::snprintf(text, sizeof(text), "follows the drift (within %.2g deg)",
                  std::max(1.0, f.drift_tolerance) * result.rotation_threshold_deg);
    return text;
  }
  return f.inlier ? "ok" : "ok (not in fit)";
}

std::string VerifyAgreementText(const VerifyResult& result) {
  if (result.compared == 0) return "No frame has both a given and a COLMAP pose.";
  if (result.unflagged == 0) {
    return "No frame agrees within the thresholds (all " + std::to_string(result.compared) +
           " compared frames are flagged).";
  }
  // The unflagged frames that do not count as agreeing, by kind: said, so that the counts
  // add up to the frames not flagged.
  std::string others;
  const auto add = [&](int count, const char* what) {
    if (count > 0) others += ", " + std::to_string(count) + " " + what;
  };
  add(result.borderline, "are borderline");
  add(result.following_drift, "follow the drift");
  add(result.weak_support, "were not judged");
  char text[400];
  if (others.empty()) {
    std::snprintf(text, sizeof(text),
                  "The %d unflagged frames agree within %.3f deg and %.4f m (median %.3f deg, "
                  "%.4f m).",
                  result.unflagged, result.max_unflagged_rotation_error_deg,
                  result.max_unflagged_position_error_m, result.median_rotation_error_deg,
                  result.median_position_error_m);
    return text;
  }
  const size_t last = others.rfind(", ");
  if (last != 0) others.replace(last, 2, " and ");
  std::snprintf(text, sizeof(text),
                "Of the %d unflagged frames, %d agree within %.3f deg and %.4f m (median %.3f "
                "deg, %.4f m)%s.",
                result.compared - result.flagged, result.unflagged,
                result.max_unflagged_rotation_error_deg, result.max_unflagged_position_error_m,
                result.median_rotation_error_deg, result.median_position_error_m, others.c_str());
  return text;
}

}  // namespace fresco
