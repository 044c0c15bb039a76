#include "pipeline/paint/joint_pose_adjustment.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "pipeline/core/scaled_camera.h"
#include "pipeline/render/rasterizer.h"

namespace fresco {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// A corner of one frame on the mesh: its pixel, its ray (normalized, z = 1, camera frame) and
// the plane of the triangle it shows (local coordinates: normal . X = offset).
struct Corner {
  cv::Point2f pixel;
  Eigen::Vector3d ray;
  Eigen::Vector3d normal;
  double offset = 0;
  Eigen::Vector3d point_local;  // where the given pose puts it
};

struct FrameData {
  cv::Mat grey;      // exposure-normalised
  cv::Mat depth;     // CV_32F camera z at the given pose
  cv::Mat triangle;  // CV_32S triangle id there (-1: none)
  std::vector<Corner> corners;
};

struct Match {
  int i = 0, j = 0;
  Eigen::Vector3d ray, normal;
  double offset = 0;
  Eigen::Vector2d pixel_j;
};

Rigid3d Corrected(const Vec6& x, const Rigid3d& given) {
  return Rigid3d(Rigid3d::QuaternionFromAxisAngle(x.head<3>()), x.tail<3>()) * given;
}

// Frame j's pixel of the point frame i's ray meets the plane at, both poses corrected.
bool Predict(const Match& m, const Camera& camera_j, const Rigid3d& pose_i, const Rigid3d& pose_j,
             Eigen::Vector2d* pixel) {
  const Eigen::Vector3d centre = pose_i.Centre();
  const Eigen::Vector3d direction = pose_i.rotation.conjugate() * m.ray;
  const double denom = m.normal.dot(direction);
  if (std::abs(denom) < 1e-9) return false;
  const double s = (m.offset - m.normal.dot(centre)) / denom;
  if (!(s > 0)) return false;
  return camera_j.Project(pose_j * (centre + s * direction), pixel);
}

cv::Mat NormalisedGrey(const cv::Mat& image) {
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else
    grey = image;
  const double mean = cv::mean(grey)[0];
  cv::Mat out;
  grey.convertTo(out, CV_8U, mean > 1 ? 110.0 / mean : 1.0);
  return out;
}

Mat6& Block(std::map<std::pair<int, int>, Mat6>* blocks, int a, int b) {
  return blocks->try_emplace({a, b}, Mat6::Zero()).first->second;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Large frames are tracked halved (as often as needed) down to max_side_px, with their
// cameras scaled alike; a frame of another size than its camera's is kept as it is (it then
// takes no part). The scaled cameras are kept in `scaled_cameras`.
std::vector<PoseAdjustFrame> TrackedFrames(
    const std::vector<PoseAdjustFrame>& given, int max_side_px,
    std::map<const Camera*, std::unique_ptr<Camera>>* scaled_cameras) {
  std::vector<PoseAdjustFrame> frames = given;
  for (PoseAdjustFrame& f : frames) {
    const Camera& camera = *f.camera;
    if (f.bgr.size() != cv::Size(camera.width, camera.height)) continue;
    int halvings = 0;
    while (max_side_px > 0 && (std::max(camera.width, camera.height) >> halvings) > max_side_px)
      ++halvings;
    if (halvings == 0) continue;
    for (int h = 0; h < halvings; ++h) cv::pyrDown(f.bgr, f.bgr);
    auto& scaled = (*scaled_cameras)[f.camera];
    if (!scaled) scaled = std::make_unique<Camera>(ScaledCamera(camera, f.bgr.cols, f.bgr.rows));
    f.camera = scaled.get();
  }
  return frames;
}

// The longer side `camera`'s frames are tracked at (TrackedFrames).
int TrackedLongSide(const Camera& camera, int max_side_px) {
  int side = std::max(camera.width, camera.height);
  while (max_side_px > 0 && side > max_side_px) side >>= 1;
  return side;
}

// Per camera: each pixel's normalised ray (x, y; NaN where the lens model has none).
std::map<const Camera*, cv::Mat> RayTables(const std::vector<PoseAdjustFrame>& frames) {
  std::map<const Camera*, cv::Mat> rays;
  for (const PoseAdjustFrame& f : frames) {
    cv::Mat& table = rays[f.camera];
    if (!table.empty()) continue;
    table.create(f.camera->height, f.camera->width, CV_32FC2);
    cv::parallel_for_(cv::Range(0, table.rows), [&](const cv::Range& r) {
      for (int y = r.start; y < r.end; ++y)
        for (int x = 0; x < table.cols; ++x) {
          Eigen::Vector2d normalized;
          const bool ok = f.camera->Unproject(Eigen::Vector2d(x, y), &normalized, 1e-3);
          table.at<cv::Vec2f>(y, x) =
              ok ? cv::Vec2f(normalized.x(), normalized.y()) : cv::Vec2f(NAN, NAN);
        }
    });
  }
  return rays;
}

// Where corners are looked for: on the surface, away from depth edges. Inverse depth is
// linear across a plane's image (up to the lens's distortion): where its second difference
// over 3 pixels is large, the surface folds or ends.
cv::Mat CornerMask(const RasterOutput& raster) {
  cv::Mat inverse_depth;
  cv::divide(1.0, raster.depth, inverse_depth, CV_32F);  // 1 / inf = 0 off the surface
  const cv::Mat second = (cv::Mat_<float>(1, 7) << 1, 0, 0, -2, 0, 0, 1);
  cv::Mat across, down;
  cv::filter2D(inverse_depth, across, CV_32F, second, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  cv::filter2D(inverse_depth, down, CV_32F, second.t(), cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  return (raster.triangle_id >= 0) & (cv::abs(across) < 0.01f * inverse_depth) &
         (cv::abs(down) < 0.01f * inverse_depth);
}

// The corners at `points` that lie on the surface, each with its ray, the plane of the
// triangle it shows and where its ray meets that plane at the given pose.
std::vector<Corner> CornersOnSurface(const TriangleMesh& mesh, const PoseAdjustFrame& in,
                                     const RasterOutput& raster,
                                     const std::vector<cv::Point2f>& points) {
  std::vector<Corner> corners;
  const Rigid3d local_from_cam = in.cam_from_local.Inverse();
  for (const cv::Point2f& p : points) {
    const int c = std::clamp(static_cast<int>(std::lround(p.x)), 0, raster.depth.cols - 1);
    const int r = std::clamp(static_cast<int>(std::lround(p.y)), 0, raster.depth.rows - 1);
    const int tri = raster.triangle_id.at<int>(r, c);
    if (tri < 0) continue;
    Eigen::Vector2d normalized;
    if (!in.camera->Unproject(Eigen::Vector2d(p.x, p.y), &normalized)) continue;
    Corner k;
    k.pixel = p;
    k.ray = Eigen::Vector3d(normalized.x(), normalized.y(), 1.0);
    k.normal = mesh.Normal(tri);
    if (k.normal.squaredNorm() < 0.5) continue;
    k.offset = k.normal.dot(mesh.Corner(tri, 0));
    // The ray's hit on the plane at the given pose.
    const Eigen::Vector3d centre = in.cam_from_local.Centre();
    const Eigen::Vector3d direction = local_from_cam.rotation * k.ray;
    const double denom = k.normal.dot(direction);
    if (std::abs(denom) < 0.05 * direction.norm()) continue;  // grazing
    k.point_local = centre + (k.offset - k.normal.dot(centre)) / denom * direction;
    corners.push_back(k);
  }
  return corners;
}

// One frame's depth and triangles at the given pose and its corners on the surface away
// from depth edges (where the mesh's silhouette, and so the plane, is least certain).
// False for a frame of another size than its camera's: it takes no part (no corners, never
// tracked into).
bool PrepareFrame(const TriangleMesh& mesh, const PoseAdjustFrame& in, const Rasterizer& rasterizer,
                  const PoseAdjustOptions& options, FrameData* d) {
  RasterOutput raster;
  rasterizer.Rasterize(mesh, in.cam_from_local, &raster);
  if (in.bgr.size() != raster.depth.size()) return false;
  d->grey = NormalisedGrey(in.bgr);
  d->depth = raster.depth;
  d->triangle = raster.triangle_id;
  std::vector<cv::Point2f> points;
  cv::goodFeaturesToTrack(d->grey, points, options.max_corners, 0.01,
                          options.min_corner_distance_px, CornerMask(raster), 5);
  d->corners = CornersOnSurface(mesh, in, raster, points);
  return true;
}

// Each pixel's surface point in frame i's camera frame, exactly on the plane of the
// triangle it sees (NaN off the surface): then each pair's warp is a transform and a
// projection per pixel. (A map interpolated between grid points bends the warp where
// perspective is strong, a road ahead, and the tracks then pull the poses.)
cv::Mat SurfacePoints(const TriangleMesh& mesh, const Rigid3d& cam_from_local,
                      const cv::Mat& triangle, const cv::Mat& ray_table) {
  cv::Mat surface(triangle.size(), CV_32FC3, cv::Scalar::all(NAN));
  int cached_triangle = -1;
  Eigen::Vector3d normal_i = Eigen::Vector3d::Zero();  // set at the first triangle
  double offset_i = 0;
  for (int y = 0; y < surface.rows; ++y)
    for (int x = 0; x < surface.cols; ++x) {
      const int tri = triangle.at<int>(y, x);
      const cv::Vec2f ray_xy = ray_table.at<cv::Vec2f>(y, x);
      if (tri < 0 || !std::isfinite(ray_xy[0])) continue;
      if (tri != cached_triangle) {
        normal_i = cam_from_local.rotation * mesh.Normal(tri);
        offset_i = normal_i.dot(cam_from_local * mesh.Corner(tri, 0));
        cached_triangle = tri;
      }
      const Eigen::Vector3d ray(ray_xy[0], ray_xy[1], 1.0);
      const double denom = normal_i.dot(ray);
      if (std::abs(denom) < 1e-6) continue;
      const Eigen::Vector3d point = offset_i / denom * ray;
      surface.at<cv::Vec3f>(y, x) = cv::Vec3f(point.x(), point.y(), point.z());
    }
  return surface;
}

// Where each pixel of frame i (its surface points) falls in frame j.
cv::Mat MapIntoFrame(const cv::Mat& surface, const Camera& camera_j, const Rigid3d& j_from_i) {
  cv::Mat map_full(surface.size(), CV_32FC2, cv::Scalar(-1000, -1000));
  for (int y = 0; y < map_full.rows; ++y)
    for (int x = 0; x < map_full.cols; ++x) {
      const cv::Vec3f point = surface.at<cv::Vec3f>(y, x);
      if (!std::isfinite(point[0])) continue;
      Eigen::Vector2d pixel;
      if (camera_j.Project(j_from_i * Eigen::Vector3d(point[0], point[1], point[2]), &pixel))
        map_full.at<cv::Vec2f>(y, x) = cv::Vec2f(pixel.x(), pixel.y());
    }
  return map_full;
}

// One frame of a pair as matching reads it.
struct View {
  int index = 0;
  const PoseAdjustFrame* frame = nullptr;
  const FrameData* data = nullptr;
};

// The corners of frame i that the given poses put inside frame j and visible there: their
// pixels in frame i (`from`) and their indices (`which`).
void CornersSeenIn(const View& a, const View& b, std::vector<cv::Point2f>* from,
                   std::vector<int>* which) {
  const std::vector<Corner>& corners = a.data->corners;
  const cv::Mat& depth_j = b.data->depth;
  for (size_t k = 0; k < corners.size(); ++k) {
    const Eigen::Vector3d in_j = b.frame->cam_from_local * corners[k].point_local;
    Eigen::Vector2d pixel;
    if (!b.frame->camera->Project(in_j, &pixel)) continue;
    const int c = static_cast<int>(std::lround(pixel.x()));
    const int r = static_cast<int>(std::lround(pixel.y()));
    if (c < 12 || r < 12 || c >= depth_j.cols - 12 || r >= depth_j.rows - 12) continue;
    const float z = depth_j.at<float>(r, c);
    if (!(std::abs(z - in_j.z()) < 0.05 * in_j.z())) continue;  // hidden in frame j
    from->push_back(corners[k].pixel);
    which->push_back(static_cast<int>(k));
  }
}

// Frame j is reprojected into frame i's view through the mesh at the given poses, frame i's
// corners are tracked into it, and a track's end is carried back to frame j's pixel through
// the mesh; the matches kept are appended to `out`.
void MatchPair(const View& a, const View& b, const cv::Mat& surface_i, const Rigid3d& local_from_i,
               const PoseAdjustOptions& options, std::vector<Match>* out) {
  const Camera& camera_i = *a.frame->camera;
  const Camera& camera_j = *b.frame->camera;
  const Rigid3d j_from_i = b.frame->cam_from_local * local_from_i;
  const cv::Mat map_full = MapIntoFrame(surface_i, camera_j, j_from_i);
  cv::Mat j_in_i;
  cv::remap(b.data->grey, j_in_i, map_full, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  std::vector<cv::Point2f> from, to;
  std::vector<int> which;
  CornersSeenIn(a, b, &from, &which);
  if (from.size() < 8) return;
  to = from;
  std::vector<uchar> status, back_status;
  std::vector<float> error;
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.003);
  const cv::Size window(options.window_px, options.window_px);
  cv::calcOpticalFlowPyrLK(a.data->grey, j_in_i, from, to, status, error, window, 2, criteria,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  std::vector<cv::Point2f> back = from;
  cv::calcOpticalFlowPyrLK(j_in_i, a.data->grey, to, back, back_status, error, window, 2, criteria,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  for (size_t k = 0; k < from.size(); ++k) {
    if (!status[k] || !back_status[k]) continue;
    if (cv::norm(back[k] - from[k]) > options.forward_backward_px) continue;
    if (cv::norm(to[k] - from[k]) > options.search_px) continue;
    const Corner& corner = a.data->corners[which[k]];
    // The track's end, through frame i's ray and the corner's plane, into frame j.
    Eigen::Vector2d normalized, pixel_j;
    if (!camera_i.Unproject(Eigen::Vector2d(to[k].x, to[k].y), &normalized)) continue;
    Match m;
    m.i = a.index, m.j = b.index;
    m.ray = Eigen::Vector3d(normalized.x(), normalized.y(), 1.0);
    m.normal = corner.normal, m.offset = corner.offset;
    if (!Predict(m, camera_j, a.frame->cam_from_local, b.frame->cam_from_local, &pixel_j)) continue;
    m.ray = corner.ray;
    m.pixel_j = pixel_j;
    out->push_back(m);
  }
}

// Deterministic order whatever the threads did.
void SortMatches(std::vector<Match>* matches) {
  std::sort(matches->begin(), matches->end(), [](const Match& x, const Match& y) {
    if (x.i != y.i) return x.i < y.i;
    if (x.j != y.j) return x.j < y.j;
    if (x.ray.x() != y.ray.x()) return x.ray.x() < y.ray.x();
    return x.ray.y() < y.ray.y();
  });
}

// Matches: frame j is reprojected into frame i's view through the mesh at the given poses
// (so that what both see looks alike there, but for the pose errors), frame i's corners are
// tracked into it, and a track's end is carried back to frame j's pixel through the mesh.
// Kept when the track comes back and the point is visible in frame j.
// Frame i is matched to i + each of `offsets` (increasing); `rays`: RayTables(frames).
std::vector<Match> FindMatches(const TriangleMesh& mesh, const std::vector<PoseAdjustFrame>& frames,
                               const std::vector<FrameData>& data,
                               const std::map<const Camera*, cv::Mat>& rays,
                               const std::vector<int>& offsets, const PoseAdjustOptions& options) {
  const int n = static_cast<int>(frames.size());
  std::vector<Match> matches;
  std::mutex matches_mutex;
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& range) {
    std::vector<Match> local;
    for (int i = range.start; i < range.end; ++i) {
      const FrameData& a = data[i];
      if (a.corners.empty()) continue;
      const Rigid3d local_from_i = frames[i].cam_from_local.Inverse();
      const cv::Mat surface =
          SurfacePoints(mesh, frames[i].cam_from_local, a.triangle, rays.at(frames[i].camera));
      for (int offset : offsets) {
        const int j = i + offset;
        if (j >= n) break;
        if (data[j].grey.empty()) continue;
        MatchPair(View{i, &frames[i], &a}, View{j, &frames[j], &data[j]}, surface, local_from_i,
                  options, &local);
      }
    }
    std::lock_guard<std::mutex> lock(matches_mutex);
    matches.insert(matches.end(), local.begin(), local.end());
  });
  SortMatches(&matches);
  return matches;
}

// Which ends of a track take their correction when its residual is measured.
enum class CorrectedEnds { kBoth, kFirst, kSecond };

// Each match's residual (pixels; 1e9 where it cannot be predicted) at the corrections `x`
// (at the given pose, the end `ends` leaves out).
void Residuals(const std::vector<PoseAdjustFrame>& frames, const std::vector<Match>& matches,
               const std::vector<Vec6>& x, std::vector<double>* residual,
               CorrectedEnds ends = CorrectedEnds::kBoth) {
  std::vector<Rigid3d> poses(frames.size());
  for (size_t f = 0; f < frames.size(); ++f) poses[f] = Corrected(x[f], frames[f].cam_from_local);
  residual->resize(matches.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(matches.size())), [&](const cv::Range& r) {
    for (int k = r.start; k < r.end; ++k) {
      const Match& m = matches[k];
      const Rigid3d& pose_i =
          ends == CorrectedEnds::kSecond ? frames[m.i].cam_from_local : poses[m.i];
      const Rigid3d& pose_j =
          ends == CorrectedEnds::kFirst ? frames[m.j].cam_from_local : poses[m.j];
      Eigen::Vector2d p;
      (*residual)[k] =
          Predict(m, *frames[m.j].camera, pose_i, pose_j, &p) ? (p - m.pixel_j).norm() : 1e9;
    }
  });
}

// Where a track counts as wrong at the start: residuals beyond max(3 px, 4 x their median).
double WrongTrackLimit(const std::vector<double>& residual) {
  std::vector<double> finite;
  for (double r : residual)
    if (r < 1e8) finite.push_back(r);
  return std::max(3.0, 4.0 * Median(finite));
}

// Gauss-Newton over all corrections (6 per frame), Huber-weighted, with the prior.
class CorrectionSolver {
 public:
  CorrectionSolver(const std::vector<PoseAdjustFrame>& frames, const std::vector<Match>& matches,
                   const PoseAdjustOptions& options)
      : frames_(frames),
        matches_(matches),
        options_(options),
        n_(static_cast<int>(frames.size())),
        dof_(options.translation ? 6 : 3),
        match_weight_(1.0 / (options.match_sigma_px * options.match_sigma_px)),
        x_(n_, Vec6::Zero()),
        rotation_sigma_(options.rotation_prior_deg * M_PI / 180.0),
        translation_sigma_(options.translation_prior_m),
        residual_(matches.size(), 0) {
    UpdateResiduals();
    KeepStartingInliers();
  }

  // Rounds: the first with the given priors; each further one with priors from the
  // corrections the previous found (per axis, their RMS times `prior_from_corrections`,
  // never below the given priors): poses noisier than assumed are not held back.
  void Run() {
    for (int round = 0; round <= options_.prior_rounds; ++round) {
      if (round > 0) PriorsFromCorrections();
      const double rot_prior = 1.0 / (rotation_sigma_ * rotation_sigma_);
      const double trans_prior = 1.0 / (translation_sigma_ * translation_sigma_);
      for (int iteration = 0; iteration < options_.iterations; ++iteration) {
        if (round == 0 && iteration == options_.weigh_gaps_after && iteration > 0) WeighGaps();
        if (!Step(rot_prior, trans_prior)) break;
      }
    }
  }

  // Each match's residual (pixels; 1e9 where it cannot be predicted) at the corrections.
  void UpdateResiduals() { Residuals(frames_, matches_, x_, &residual_); }

  // Whether match k counts as an inlier at the last residuals.
  bool Inlier(size_t k) const { return use_[k] && residual_[k] < 3 * options_.huber_px; }

  // RMS of the inliers' residuals.
  double Rms() const {
    double sum = 0;
    int count = 0;
    for (size_t k = 0; k < residual_.size(); ++k)
      if (Inlier(k)) sum += residual_[k] * residual_[k], ++count;
    return count > 0 ? std::sqrt(sum / count) : 0.0;
  }

  const std::vector<Vec6>& corrections() const { return x_; }
  double rotation_sigma() const { return rotation_sigma_; }
  double translation_sigma() const { return translation_sigma_; }

 private:
  using Blocks = std::map<std::pair<int, int>, Mat6>;

  // Matches far off at the start (wrong tracks, movers) stay out.
  void KeepStartingInliers() {
    use_.assign(matches_.size(), 0);
    const double limit = WrongTrackLimit(residual_);
    for (size_t k = 0; k < matches_.size(); ++k) use_[k] = residual_[k] < limit;
  }

  // Tracks over longer gaps are noisier (the views differ more: 0.26 px RMS at one frame, 1 px
  // at 16 on a street walk) and a little biased, while they are what fixes slow drifts of the
  // poses: once the poses are mostly corrected, each gap's matches are weighted by the inverse
  // of their spread (relative to the tightest gap's).
  void WeighGaps() {
    UpdateResiduals();
    std::map<int, std::pair<double, int>> spread;  // gap: sum of squares, count
    for (size_t k = 0; k < matches_.size(); ++k)
      if (Inlier(k)) {
        auto& [sum, count] = spread[matches_[k].j - matches_[k].i];
        sum += residual_[k] * residual_[k], ++count;
      }
    double tightest = std::numeric_limits<double>::infinity();
    for (const auto& [gap, sc] : spread) tightest = std::min(tightest, sc.first / sc.second);
    for (const auto& [gap, sc] : spread)
      gap_weight_[gap] = std::min(1.0, tightest / std::max(1e-12, sc.first / sc.second));
  }

  // The priors from the corrections found so far (never below the given priors).
  void PriorsFromCorrections() {
    double rotation2 = 0, translation2 = 0;
    for (int f = 0; f < n_; ++f)
      rotation2 += x_[f].head<3>().squaredNorm(), translation2 += x_[f].tail<3>().squaredNorm();
    const double k = options_.prior_from_corrections;
    rotation_sigma_ =
        std::max(options_.rotation_prior_deg * M_PI / 180.0, k * std::sqrt(rotation2 / (3.0 * n_)));
    translation_sigma_ =
        std::max(options_.translation_prior_m, k * std::sqrt(translation2 / (3.0 * n_)));
  }

  // Adds each used match's blocks of J^T W J per frame pair (i <= j) and J^T W r per frame,
  // with J by forward differences.
  void AddMatches(const std::vector<Rigid3d>& poses, Blocks* blocks,
                  std::vector<Vec6>* gradient) const {
    const double step = 1e-7;
    for (size_t k = 0; k < matches_.size(); ++k) {
      if (!use_[k]) continue;
      const Match& m = matches_[k];
      const Camera& camera_j = *frames_[m.j].camera;
      Eigen::Vector2d p0;
      if (!Predict(m, camera_j, poses[m.i], poses[m.j], &p0)) continue;
      const Eigen::Vector2d r = p0 - m.pixel_j;
      const double norm = r.norm();
      double w = match_weight_ * (norm <= options_.huber_px ? 1.0 : options_.huber_px / norm);
      if (const auto it = gap_weight_.find(m.j - m.i); it != gap_weight_.end()) w *= it->second;
      Eigen::Matrix<double, 2, 12> J;
      bool ok = true;
      for (int q = 0; q < 12 && ok; ++q) {
        Vec6 xi = x_[m.i], xj = x_[m.j];
        (q < 6 ? xi : xj)[q % 6] += step;
        Eigen::Vector2d p;
        ok = Predict(m, camera_j, Corrected(xi, frames_[m.i].cam_from_local),
                     Corrected(xj, frames_[m.j].cam_from_local), &p);
        J.col(q) = (p - p0) / step;
      }
      if (!ok) continue;
      const Eigen::Matrix<double, 2, 6> Ji = J.leftCols<6>(), Jj = J.rightCols<6>();
      Block(blocks, m.i, m.i) += w * Ji.transpose() * Ji;
      Block(blocks, m.j, m.j) += w * Jj.transpose() * Jj;
      Block(blocks, m.i, m.j) += w * Ji.transpose() * Jj;
      (*gradient)[m.i] += w * Ji.transpose() * r;
      (*gradient)[m.j] += w * Jj.transpose() * r;
    }
  }

  // Adds the priors to the diagonal blocks; returns the right-hand side, -(J^T W r + prior).
  Eigen::VectorXd AddPriors(double rot_prior, double trans_prior, const std::vector<Vec6>& gradient,
                            Blocks* blocks) const {
    Eigen::VectorXd rhs(n_ * dof_);
    for (int f = 0; f < n_; ++f) {
      Mat6& d = Block(blocks, f, f);
      Vec6 g = gradient[f];
      for (int c = 0; c < 3; ++c) d(c, c) += rot_prior, g[c] += rot_prior * x_[f][c];
      for (int c = 3; c < 6; ++c) d(c, c) += trans_prior, g[c] += trans_prior * x_[f][c];
      for (int c = 0; c < dof_; ++c) rhs[f * dof_ + c] = -g[c];
    }
    return rhs;
  }

  // The symmetric sparse matrix of the blocks (of the first dof_ rows and columns each).
  Eigen::SparseMatrix<double> Assemble(const Blocks& blocks) const {
    std::vector<Eigen::Triplet<double>> triplets;
    for (const auto& [key, block] : blocks) {
      const auto [a, b] = key;
      for (int r = 0; r < dof_; ++r)
        for (int c = 0; c < dof_; ++c) {
          if (block(r, c) == 0) continue;
          triplets.emplace_back(a * dof_ + r, b * dof_ + c, block(r, c));
          if (a != b) triplets.emplace_back(b * dof_ + c, a * dof_ + r, block(r, c));
        }
    }
    Eigen::SparseMatrix<double> H(n_ * dof_, n_ * dof_);
    H.setFromTriplets(triplets.begin(), triplets.end());
    return H;
  }

  // One Gauss-Newton step; false when the solve fails or the step is negligible.
  bool Step(double rot_prior, double trans_prior) {
    std::vector<Rigid3d> poses(n_);
    for (int f = 0; f < n_; ++f) poses[f] = Corrected(x_[f], frames_[f].cam_from_local);
    Blocks blocks;
    std::vector<Vec6> gradient(n_, Vec6::Zero());
    AddMatches(poses, &blocks, &gradient);
    const Eigen::VectorXd rhs = AddPriors(rot_prior, trans_prior, gradient, &blocks);
    const Eigen::SparseMatrix<double> H = Assemble(blocks);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(H);
    if (solver.info() != Eigen::Success) return false;
    const Eigen::VectorXd delta = solver.solve(rhs);
    if (solver.info() != Eigen::Success || !delta.allFinite()) return false;
    double largest = 0;
    for (int f = 0; f < n_; ++f) {
      x_[f].head(dof_) += delta.segment(f * dof_, dof_);
      largest = std::max(largest, delta.segment(f * dof_, dof_).cwiseAbs().maxCoeff());
    }
    return largest >= 1e-8;
  }

  const std::vector<PoseAdjustFrame>& frames_;
  const std::vector<Match>& matches_;
  const PoseAdjustOptions& options_;
  const int n_;
  const int dof_;
  const double match_weight_;
  std::vector<Vec6> x_;
  double rotation_sigma_;
  double translation_sigma_;
  std::vector<double> residual_;
  std::vector<char> use_;
  std::map<int, double> gap_weight_;
};

// The result's figures from the solve: inliers, whether the corrections are applied, the
// corrected poses and the corrections' medians.
void Summarise(const std::vector<PoseAdjustFrame>& frames, const std::vector<Match>& matches,
               const CorrectionSolver& solver, const PoseAdjustOptions& options,
               PoseAdjustResult* result) {
  for (size_t k = 0; k < matches.size(); ++k)
    if (solver.Inlier(k)) {
      ++result->inliers;
      ++result->frame_matches[matches[k].i];
      ++result->frame_matches[matches[k].j];
    }
  result->applied = result->rms_after_px > 0;
  const std::vector<Vec6>& x = solver.corrections();
  std::vector<double> rotations, translations;
  for (size_t f = 0; f < frames.size(); ++f) {
    if (result->applied) result->cam_from_local[f] = Corrected(x[f], frames[f].cam_from_local);
    rotations.push_back(x[f].head<3>().norm() * 180.0 / M_PI);
    translations.push_back(x[f].tail<3>().norm());
  }
  result->rotation_prior_deg = solver.rotation_sigma() * 180.0 / M_PI;
  result->translation_prior_m = solver.translation_sigma();
  result->median_rotation_deg = Median(rotations);
  result->median_translation_m = Median(translations);
}

// The frames as tracked (TrackedFrames), each prepared (PrepareFrame).
struct Prepared {
  std::map<const Camera*, std::unique_ptr<Camera>> scaled_cameras;
  std::vector<PoseAdjustFrame> frames;
  std::vector<FrameData> data;
  std::map<const Camera*, cv::Mat> rays;  // RayTables(frames)
};

void Prepare(const TriangleMesh& mesh, const std::vector<PoseAdjustFrame>& given,
             const PoseAdjustOptions& options, Prepared* prepared) {
  const int n = static_cast<int>(given.size());
  prepared->frames = TrackedFrames(given, options.max_side_px, &prepared->scaled_cameras);
  std::map<const Camera*, std::unique_ptr<Rasterizer>> rasterizers;
  for (const PoseAdjustFrame& frame : prepared->frames) {
    auto& rasterizer = rasterizers[frame.camera];
    if (!rasterizer) rasterizer = std::make_unique<Rasterizer>(*frame.camera, RasterOptions());
  }
  prepared->data.resize(n);
  // Frames at once (a frame's rasterizing and corner finding are mostly on one core).
  std::atomic<int> done{0};
  std::mutex progress_mutex;
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& range) {
    for (int f = range.start; f < range.end; ++f) {
      const PoseAdjustFrame& frame = prepared->frames[f];
      PrepareFrame(mesh, frame, *rasterizers.at(frame.camera), options, &prepared->data[f]);
      const int count = ++done;
      if (options.progress && (count % std::max(1, n / 4) == 0 || count == n)) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        options.progress(count, 2 * n + options.iterations, "frames prepared");
      }
    }
  });
  prepared->rays = RayTables(prepared->frames);
}

// PoseAdjustOptions' check from `tracks` (over check_offsets): the even and the odd frames each
// adjusted from the tracks between their own frames only, the tracks between the halves
// measured at the given poses, with one end at its half's correction (both ways) and with both
// (the RMS of each residual capped at WrongTrackLimit at the given poses, over the tracks
// within it at the given poses or with both corrected).
void CheckOnFramesLeftOut(const std::vector<PoseAdjustFrame>& frames,
                          const std::vector<Match>& tracks, const PoseAdjustOptions& options,
                          PoseAdjustResult* result) {
  std::vector<Match> within, between;
  for (const Match& m : tracks) ((m.j - m.i) % 2 == 0 ? within : between).push_back(m);
  if (within.empty() || between.empty()) return;
  CorrectionSolver halves(frames, within, options);
  halves.Run();
  std::vector<double> before, after, first, second;
  Residuals(frames, between, std::vector<Vec6>(frames.size(), Vec6::Zero()), &before);
  Residuals(frames, between, halves.corrections(), &after);
  Residuals(frames, between, halves.corrections(), &first, CorrectedEnds::kFirst);
  Residuals(frames, between, halves.corrections(), &second, CorrectedEnds::kSecond);
  const double limit = WrongTrackLimit(before);
  double sum_before = 0, sum_after = 0, sum_one_end = 0;
  for (size_t k = 0; k < between.size(); ++k) {
    if (before[k] >= limit && after[k] >= limit) continue;
    sum_before += std::pow(std::min(before[k], limit), 2);
    sum_after += std::pow(std::min(after[k], limit), 2);
    sum_one_end +=
        0.5 * (std::pow(std::min(first[k], limit), 2) + std::pow(std::min(second[k], limit), 2));
    ++result->check_matches;
  }
  if (result->check_matches == 0) return;
  result->check_before_px = std::sqrt(sum_before / result->check_matches);
  result->check_after_px = std::sqrt(sum_after / result->check_matches);
  result->check_one_end_px = std::sqrt(sum_one_end / result->check_matches);
}

}  // namespace

std::string TooManyFramesToAdjust(int frames, const PoseAdjustOptions& options) {
  if (options.max_frames <= 0 || frames <= options.max_frames) return "";
  return std::to_string(frames) + " frames, more than the " + std::to_string(options.max_frames) +
         " it holds in memory";
}

Status AdjustPosesOnMesh(const TriangleMesh& mesh, const std::vector<PoseAdjustFrame>& given,
                         const PoseAdjustOptions& options, PoseAdjustResult* result) {
  const auto start = std::chrono::steady_clock::now();
  *result = PoseAdjustResult();
  const int n = static_cast<int>(given.size());
  for (const PoseAdjustFrame& f : given) result->cam_from_local.push_back(f.cam_from_local);
  result->frame_matches.assign(n, 0);
  if (n < 2) {
    result->not_run = "fewer than two frames";
    return Status::Ok();
  }
  result->not_run = TooManyFramesToAdjust(n, options);
  if (!result->not_run.empty()) return Status::Ok();
  const auto seconds = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  result->decided_on_frames = n;
  // A long capture is decided on its first frames; a short one whose frames are tracked
  // smaller to decide is decided on all of them at that size first.
  const int first_frames = options.decide_on_first_frames;
  const bool long_capture = first_frames >= 2 && 2 * n > 3 * first_frames;
  const bool smaller_to_decide = options.decide_max_side_px > 0 &&
                                 TrackedLongSide(*given[0].camera, options.decide_max_side_px) <
                                     TrackedLongSide(*given[0].camera, options.max_side_px);
  if (long_capture || smaller_to_decide) {
    PoseAdjustOptions on_first = options;
    on_first.decide_on_first_frames = 0;
    on_first.decide_max_side_px = 0;
    if (options.decide_max_side_px > 0) on_first.max_side_px = options.decide_max_side_px;
    if (options.progress)  // the first frames' steps, then the whole capture's
      on_first.progress = [&options, long_capture](int done, int total, const std::string& line) {
        options.progress(done, total, (long_capture ? "first frames: " : "deciding: ") + line);
      };
    PoseAdjustResult trial;
    const std::vector<PoseAdjustFrame> deciding(given.begin(),
                                                given.begin() + (long_capture ? first_frames : n));
    FRESCO_RETURN_IF_ERROR(AdjustPosesOnMesh(mesh, deciding, on_first, &trial));
    if (!trial.applied && trial.not_run.empty()) {
      const std::vector<Rigid3d> poses = result->cam_from_local;
      std::vector<int> frame_matches = trial.frame_matches;
      frame_matches.resize(n, 0);
      *result = trial;
      result->cam_from_local = poses;
      result->frame_matches = frame_matches;
      result->seconds = seconds();
      if (options.progress)
        options.progress(1, 1,
                         long_capture ? "decided on the first frames: not adjusted"
                                      : "decided on smaller frames: not adjusted");
      return Status::Ok();
    }
  }
  Prepared prepared;
  Prepare(mesh, given, options, &prepared);
  // The check's tracks first (over check_offsets), then the others'.
  const bool check = options.check_min_improvement > 0;
  std::vector<int> first, rest;
  for (int offset : options.offsets)
    (check && std::count(options.check_offsets.begin(), options.check_offsets.end(), offset)
         ? first
         : rest)
        .push_back(offset);
  std::vector<Match> matches =
      FindMatches(mesh, prepared.frames, prepared.data, prepared.rays, first, options);
  if (check) {
    CheckOnFramesLeftOut(prepared.frames, matches, options, result);
    result->check_seconds = seconds();
    const bool passed =
        result->check_one_end_px > 0 &&
        result->check_before_px >= options.check_min_improvement * result->check_one_end_px;
    if (!passed) {
      if (options.progress) options.progress(1, 1, "checked: not adjusted");
      result->seconds = seconds();
      return Status::Ok();
    }
  }
  const std::vector<Match> more =
      FindMatches(mesh, prepared.frames, prepared.data, prepared.rays, rest, options);
  matches.insert(matches.end(), more.begin(), more.end());
  SortMatches(&matches);
  prepared.data.clear();
  result->matches = static_cast<int>(matches.size());
  if (options.progress)
    options.progress(2 * n, 2 * n + options.iterations, std::to_string(matches.size()) + " tracks");
  if (matches.empty()) return Status::Ok();

  CorrectionSolver solver(prepared.frames, matches, options);
  result->rms_before_px = solver.Rms();
  solver.Run();
  solver.UpdateResiduals();
  result->rms_after_px = solver.Rms();
  if (options.progress)
    options.progress(2 * n + options.iterations, 2 * n + options.iterations, "adjusted");
  Summarise(prepared.frames, matches, solver, options, result);
  result->seconds = seconds();
  return Status::Ok();
}

}  // namespace fresco
