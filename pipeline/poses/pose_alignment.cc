#include "pipeline/poses/pose_alignment.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/SVD>

namespace fresco {
namespace {

// The rotation nearest (Frobenius) to the mean of `rotations`: the chordal L2 mean.
Eigen::Matrix3d ChordalMean(const std::vector<Eigen::Matrix3d>& rotations) {
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  for (const Eigen::Matrix3d& r : rotations) sum += r;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sum, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

double AngleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double c = std::clamp(((a.transpose() * b).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

// The inputs of one alignment, shared by its starts and refinements.
struct Problem {
  const std::vector<PosePair>& pairs;
  const PoseAlignmentOptions& options;
  std::vector<Eigen::Vector3d> colmap_centres, given_centres;
  // Each frame's own estimate of world_from_colmap's rotation: world_from_cam (given) *
  // cam_from_colmap (COLMAP).
  std::vector<Eigen::Matrix3d> frame_rotation;

  int Size() const { return static_cast<int>(pairs.size()); }

  // Inliers of `t` within the thresholds; returns their number.
  int Select(const Sim3d& t, double position_m, double rotation_deg,
             std::vector<bool>* inliers) const {
    inliers->assign(pairs.size(), false);
    int count = 0;
    for (int i = 0; i < Size(); ++i) {
      const PoseError e = ComparePose(pairs[i], t);
      if (e.position_m < position_m && e.rotation_deg < rotation_deg) (*inliers)[i] = true, ++count;
    }
    return count;
  }

  // Scale and translation for `rotation`: least squares over `use`. False when degenerate.
  bool FitScaleTranslation(const Eigen::Matrix3d& rotation, const std::vector<bool>& use,
                           Sim3d* t) const {
    Eigen::Vector3d mean_c = Eigen::Vector3d::Zero(), mean_g = Eigen::Vector3d::Zero();
    int count = 0;
    for (int i = 0; i < Size(); ++i) {
      if (use[i]) mean_c += colmap_centres[i], mean_g += given_centres[i], ++count;
    }
    if (count < 2) return false;
    mean_c /= count, mean_g /= count;
    double num = 0, den = 0;
    for (int i = 0; i < Size(); ++i) {
      if (!use[i]) continue;
      const Eigen::Vector3d c = rotation * (colmap_centres[i] - mean_c);
      num += c.dot(given_centres[i] - mean_g);
      den += c.squaredNorm();
    }
    if (!(den > 0) || !(num > 0)) return false;
    t->scale = num / den;
    t->rotation = Eigen::Quaterniond(rotation).normalized();
    t->translation = mean_g - t->scale * (rotation * mean_c);
    return true;
  }

  // Refits rotation (chordal mean), then scale and translation, on the inliers, and
  // re-selects the inliers within the thresholds, until they stop changing.
  void Refine(double position_m, double rotation_deg, Sim3d* t, std::vector<bool>* inliers) const {
    for (int round = 0; round < 3; ++round) {
      std::vector<Eigen::Matrix3d> used;
      for (int i = 0; i < Size(); ++i) {
        if ((*inliers)[i]) used.push_back(frame_rotation[i]);
      }
      if (used.size() < 3) break;
      Sim3d refined;
      if (!FitScaleTranslation(ChordalMean(used), *inliers, &refined)) break;
      std::vector<bool> next;
      if (Select(refined, position_m, rotation_deg, &next) < 3) break;
      *t = refined;
      const bool same = next == *inliers;
      *inliers = next;
      if (same) break;
    }
  }

  // Refine with the given thresholds, then with thresholds from the inliers' own spread,
  // repeated while the inliers change: poses off by less than the given thresholds but
  // clearly more than the rest stop bending the fit (a bent fit inflates the spread, so
  // one round may not be enough).
  void RefineAdaptively(Sim3d* t, std::vector<bool>* inliers) const {
    Refine(options.inlier_position_m, options.inlier_rotation_deg, t, inliers);
    for (int round = 0; options.adaptive_factor > 0 && round < 3; ++round) {
      std::vector<double> position, rotation;
      for (int i = 0; i < Size(); ++i) {
        if (!(*inliers)[i]) continue;
        const PoseError e = ComparePose(pairs[i], *t);
        position.push_back(e.position_m);
        rotation.push_back(e.rotation_deg);
      }
      if (position.size() < 6) break;
      const double kFloor = 0.05;  // of the given thresholds
      const std::vector<bool> before = *inliers;
      Refine(std::clamp(options.adaptive_factor * Median(position),
                        kFloor * options.inlier_position_m, options.inlier_position_m),
             std::clamp(options.adaptive_factor * Median(rotation),
                        kFloor * options.inlier_rotation_deg, options.inlier_rotation_deg),
             t, inliers);
      if (*inliers == before) break;
    }
  }

  // The start from the orientations: the frame rotation most others agree with, then
  // scale and translation from two of those frames' centres. False when no rotation is
  // shared by 3 frames or no scale fits.
  bool StartFromOrientations(Sim3d* t, std::vector<bool>* inliers) const {
    const int n = Size();
    std::mt19937 rng(options.seed);
    // Candidate frames: all of them up to 300, else a random 300.
    std::vector<int> candidates(n);
    for (int i = 0; i < n; ++i) candidates[i] = i;
    if (n > 300) {
      std::shuffle(candidates.begin(), candidates.end(), rng);
      candidates.resize(300);
    }
    std::vector<bool> agree;
    int best_count = 0;
    for (int c : candidates) {
      std::vector<bool> here(n, false);
      int count = 0;
      for (int j = 0; j < n; ++j) {
        if (AngleDeg(frame_rotation[c], frame_rotation[j]) < options.inlier_rotation_deg) {
          here[j] = true, ++count;
        }
      }
      if (count > best_count) best_count = count, agree = here;
    }
    if (best_count < 3) return false;
    std::vector<Eigen::Matrix3d> used;
    for (int i = 0; i < n; ++i) {
      if (agree[i]) used.push_back(frame_rotation[i]);
    }
    const Eigen::Matrix3d rotation = ChordalMean(used);
    // Scale and translation: 2-point RANSAC over the agreeing frames' centres.
    std::vector<int> pool;
    for (int i = 0; i < n; ++i) {
      if (agree[i]) pool.push_back(i);
    }
    std::uniform_int_distribution<int> pick(0, static_cast<int>(pool.size()) - 1);
    int best_inliers = -1;
    Sim3d best;
    // All agreeing frames first: with few outliers it is already the answer.
    for (int iteration = -1; iteration < options.iterations; ++iteration) {
      std::vector<bool> use = agree;
      if (iteration >= 0) {
        const int a = pool[pick(rng)], b = pool[pick(rng)];
        if (a == b) continue;
        use.assign(n, false);
        use[a] = use[b] = true;
      }
      Sim3d candidate;
      if (!FitScaleTranslation(rotation, use, &candidate)) continue;
      std::vector<bool> selected;
      const int count =
          Select(candidate, options.inlier_position_m, options.inlier_rotation_deg, &selected);
      if (count > best_inliers) best_inliers = count, best = candidate, *inliers = selected;
      if (best_inliers == static_cast<int>(pool.size())) break;
    }
    if (best_inliers < 3) return false;
    *t = best;
    return true;
  }

  // The start from the centres alone (RANSAC similarity).
  bool StartFromCentres(Sim3d* t, std::vector<bool>* inliers) const {
    RobustSimilarityOptions robust;
    robust.inlier_threshold = options.inlier_position_m;
    robust.iterations = options.iterations;
    robust.seed = options.seed;
    RobustSimilarityResult fit;
    if (!EstimateSimilarityRobust(colmap_centres, given_centres, robust, "centres", &fit).ok()) {
      return false;
    }
    *t = fit.dst_from_src;
    *inliers = fit.inliers;
    return true;
  }
};

}  // namespace

Status PoseAlignmentOptions::Check() const {
  if (!(inlier_position_m > 0)) return Status::Error("inlier_position_m: must be > 0");
  if (!(inlier_rotation_deg > 0)) return Status::Error("inlier_rotation_deg: must be > 0");
  if (iterations < 1) return Status::Error("iterations: must be >= 1");
  if (!(adaptive_factor >= 0)) return Status::Error("adaptive_factor: must be >= 0");
  if (!(collinear_ratio >= 0 && collinear_ratio < 1)) {
    return Status::Error("collinear_ratio: must be in [0, 1)");
  }
  return Status::Ok();
}

CentreSpread MeasureCentreSpread(const std::vector<Eigen::Vector3d>& centres,
                                 const PoseAlignmentOptions& options) {
  CentreSpread spread;
  if (centres.empty()) return spread;
  Eigen::Matrix3Xd m(3, centres.size());
  for (size_t i = 0; i < centres.size(); ++i) m.col(i) = centres[i];
  const Eigen::Vector3d mean = m.rowwise().mean();
  const Eigen::Matrix3Xd centred = m.colwise() - mean;
  const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::Matrix3Xd>(centred).singularValues();
  spread.rms_m = std::sqrt(centred.squaredNorm() / static_cast<double>(centres.size()));
  spread.spread_ratio = s[0] > 0 ? s[1] / s[0] : 0.0;
  spread.coincident = spread.rms_m < options.inlier_position_m;
  spread.collinear = !spread.coincident && spread.spread_ratio < options.collinear_ratio;
  return spread;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

Eigen::Matrix<double, 6, 1> DisagreementOf(const PosePair& pair, const Sim3d& world_from_colmap,
                                           double rotation_deg, double position_m) {
  const Rigid3d aligned = world_from_colmap.TransformPose(pair.colmap_cam_from_colmap);
  const Eigen::AngleAxisd w(aligned.RotationMatrix().transpose() *
                            pair.given_cam_from_world.RotationMatrix());
  Eigen::Matrix<double, 6, 1> e;
  e.head<3>() = w.angle() * w.axis() / (rotation_deg * M_PI / 180.0);
  e.tail<3>() = (aligned.Centre() - pair.given_cam_from_world.Centre()) / position_m;
  return e;
}

Disagreement MeasureDisagreement(const std::vector<PosePair>& pairs, const Sim3d& world_from_colmap,
                                 double rotation_deg, double position_m) {
  const int n = static_cast<int>(pairs.size());
  std::vector<Eigen::Matrix<double, 6, 1>> e(n);  // rotation, offset in threshold units
  std::vector<bool> beyond(n, false);
  for (int i = 0; i < n; ++i) {
    e[i] = DisagreementOf(pairs[i], world_from_colmap, rotation_deg, position_m);
    beyond[i] = e[i].head<3>().norm() > 1.0 || e[i].tail<3>().norm() > 1.0;
  }
  Disagreement d;
  for (int i = 0; i < n; ++i) {
    if (!beyond[i]) continue;
    ++d.disagreeing;
    bool smooth = false;
    for (int j : {i - 1, i + 1}) {
      if (j >= 0 && j < n && beyond[j] && (e[i] - e[j]).norm() < 0.5 * e[i].norm()) smooth = true;
    }
    if (!smooth) {
      // Or like the frames around it (their median per component, kSmoothWindow on each side),
      // however noisy from one frame to the next: a walk that bends unevenly (a 60-frame
      // street, its given poses with 0.3 degrees of noise: 19 false flags, then 3).
      constexpr int kSmoothWindow = 3;
      Eigen::Matrix<double, 6, 1> middle;
      for (int c = 0; c < 6; ++c) {
        std::vector<double> values;
        for (int j = std::max(0, i - kSmoothWindow); j <= std::min(n - 1, i + kSmoothWindow); ++j)
          if (j != i) values.push_back(e[j][c]);
        middle[c] = Median(values);
      }
      smooth = (e[i] - middle).norm() < 0.5 * e[i].norm();
    }
    if (!smooth) continue;
    ++d.smooth;
    if (d.first < 0) d.first = i;
    d.last = i;
  }
  return d;
}

PoseError ComparePose(const PosePair& pair, const Sim3d& world_from_colmap) {
  const Rigid3d aligned = world_from_colmap.TransformPose(pair.colmap_cam_from_colmap);
  PoseError error;
  error.rotation_deg = RotationDifferenceDeg(aligned.rotation, pair.given_cam_from_world.rotation);
  error.position_m = (aligned.Centre() - pair.given_cam_from_world.Centre()).norm();
  return error;
}

Status AlignColmapToPoses(const std::vector<PosePair>& pairs, const PoseAlignmentOptions& options,
                          PoseAlignment* alignment) {
  FRESCO_RETURN_IF_ERROR(options.Check());
  const int n = static_cast<int>(pairs.size());
  if (n < 3) {
    return Status::Error("an alignment needs at least 3 frames with both poses, got " +
                         std::to_string(n));
  }
  Problem problem{pairs, options, {}, {}, {}};
  for (const PosePair& p : pairs) {
    problem.colmap_centres.push_back(p.colmap_cam_from_colmap.Centre());
    problem.given_centres.push_back(p.given_cam_from_world.Centre());
    problem.frame_rotation.push_back(p.given_cam_from_world.RotationMatrix().transpose() *
                                     p.colmap_cam_from_colmap.RotationMatrix());
  }
  const CentreSpread spread = MeasureCentreSpread(problem.given_centres, options);
  if (spread.coincident) {
    char text[200];
    std::snprintf(text, sizeof(text),
                  "the %d given camera centres (nearly) coincide (RMS spread %.3g m): the scale "
                  "of COLMAP's reconstruction is undetermined",
                  n, spread.rms_m);
    return Status::Error(text);
  }
  struct Candidate {
    Sim3d t;
    std::vector<bool> inliers;
    int count = -1;
    const char* from = "";
  };
  std::vector<Candidate> candidates;
  {
    Candidate c;
    c.from = "orientations";
    if (problem.StartFromOrientations(&c.t, &c.inliers)) candidates.push_back(c);
  }
  if (!spread.Degenerate()) {
    Candidate c;
    c.from = "centres";
    if (problem.StartFromCentres(&c.t, &c.inliers)) candidates.push_back(c);
  }
  const Candidate* best = nullptr;
  for (Candidate& c : candidates) {
    problem.RefineAdaptively(&c.t, &c.inliers);
    c.count = static_cast<int>(std::count(c.inliers.begin(), c.inliers.end(), true));
    if (!best || c.count > best->count) best = &c;
  }
  if (!best || best->count < 3) {
    return Status::Error("no alignment of COLMAP's reconstruction agrees with at least 3 of the " +
                         std::to_string(n) + " given poses");
  }
  alignment->world_from_colmap = best->t;
  alignment->inliers = best->inliers;
  alignment->num_inliers = best->count;
  alignment->centres = spread;
  alignment->rotation_from = best->from;
  return Status::Ok();
}

}  // namespace fresco
