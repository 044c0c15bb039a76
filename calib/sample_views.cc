#include "calib/sample_views.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "calib/board_image.h"
#include "calib/lens_projection.h"

namespace fresco::calib {
namespace {

constexpr int kSamples = 2;        // per pixel and axis
constexpr int kTextureBitPx = 12;  // texture pixels per tag bit
constexpr double kInViewMarginPx = 2;

Eigen::Matrix3d Rotation(const std::array<double, 6>& rt) {
  const Eigen::Vector3d r(rt[0], rt[1], rt[2]);
  if (r.norm() < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix();
}

bool Inside(const Eigen::Vector2d& q, const SyntheticLens& lens) {
  return q.x() >= kInViewMarginPx && q.y() >= kInViewMarginPx &&
         q.x() <= lens.width - 1 - kInViewMarginPx && q.y() <= lens.height - 1 - kInViewMarginPx;
}

std::vector<Eigen::Vector2d> ProjectCorners(const BoardSpec& spec, const SyntheticLens& lens,
                                            const std::array<double, 6>& rt) {
  const Eigen::Matrix3d R = Rotation(rt);
  const Eigen::Vector3d t(rt[3], rt[4], rt[5]);
  std::vector<Eigen::Vector3d> points;
  for (int id = 0; id < spec.NumCorners(); ++id) points.push_back(R * CornerPosition(spec, id) + t);
  std::vector<Eigen::Vector2d> q;
  if (!ProjectPoints(lens.lensmodel, lens.intrinsics, points, &q)) q.clear();
  return q;
}

}  // namespace

SyntheticImageRenderer::SyntheticImageRenderer(const BoardSpec& spec, const SyntheticLens& lens,
                                               bool kalibr_squares)
    : spec_(spec), lens_(lens) {
  // The same layout with a tag edge of 1 inch: 10 * kTextureBitPx dpi draws kTextureBitPx
  // pixels per bit.
  BoardSpec drawn = spec;
  drawn.square_m = 0.0254;
  BoardImage image;
  if (!RenderBoardImage(drawn, 10 * kTextureBitPx, &image).ok()) return;
  const int tag_px = 10 * kTextureBitPx;
  const int gap_px = static_cast<int>(std::lround(spec.spacing * tag_px));
  const int pitch_px = tag_px + gap_px, margin = 2 * kTextureBitPx + gap_px;
  const int pattern_h = spec.rows * pitch_px - gap_px;
  texture_ = image.gray.rowRange(0, pattern_h + 2 * margin).clone();
  // Kalibr's printed AprilGrid (and the real board of aprilgrid-yac-mocap) has a black square
  // in every crossing of the gaps, touching the corners of the tags around it.
  if (kalibr_squares)
    for (int j = 0; j <= spec.rows; ++j)
      for (int i = 0; i <= spec.cols; ++i)
        texture_(cv::Rect(margin - gap_px + i * pitch_px, margin - gap_px + j * pitch_px, gap_px,
                          gap_px))
            .setTo(0);
  texture_px_per_m_ = tag_px / spec.square_m;
  texture_origin_ =
      Eigen::Vector2d(margin - 0.5, margin + (spec.rows - 1) * pitch_px + tag_px - 0.5);
  std::vector<Eigen::Vector2d> samples;
  for (int j = 0; j < kSamples * lens.height; ++j)
    for (int i = 0; i < kSamples * lens.width; ++i)
      samples.emplace_back((i + 0.5) / kSamples - 0.5, (j + 0.5) / kSamples - 0.5);
  UnprojectPixels(lens.lensmodel, lens.intrinsics, samples, &rays_);
}

SyntheticImage SyntheticImageRenderer::Render(const std::array<double, 6>& rt,
                                              const SyntheticImageOptions& options) const {
  SyntheticImage out;
  const Eigen::Matrix3d R = Rotation(rt);
  const Eigen::Vector3d t(rt[3], rt[4], rt[5]);
  const Eigen::Vector3d normal = R.col(2);
  const int w = kSamples * lens_.width, h = kSamples * lens_.height;
  cv::Mat map_x(h, w, CV_32F), map_y(h, w, CV_32F);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const Eigen::Vector3d& d = rays_[j * w + i];
      const double s = normal.dot(t) / normal.dot(d);
      float u = -1e6f, v = -1e6f;
      if (std::isfinite(s) && s > 0) {
        const Eigen::Vector3d b = R.transpose() * (s * d - t);
        u = static_cast<float>(texture_origin_.x() + b.x() * texture_px_per_m_);
        v = static_cast<float>(texture_origin_.y() - b.y() * texture_px_per_m_);
      }
      map_x.at<float>(j, i) = u;
      map_y.at<float>(j, i) = v;
    }
  cv::Mat sampled;
  cv::remap(texture_, sampled, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar(options.background));
  cv::resize(sampled, out.gray, cv::Size(lens_.width, lens_.height), 0, 0, cv::INTER_AREA);
  if (options.blur_sigma_px > 0)
    cv::GaussianBlur(out.gray, out.gray, cv::Size(0, 0), options.blur_sigma_px);
  if (options.noise_px > 0) {
    cv::Mat noise(out.gray.size(), CV_32F);
    cv::RNG rng(options.seed);
    rng.fill(noise, cv::RNG::NORMAL, 0, options.noise_px);
    cv::Mat noisy;
    out.gray.convertTo(noisy, CV_32F);
    noisy += noise;
    noisy.convertTo(out.gray, CV_8U);
  }
  out.truth = ProjectCorners(spec_, lens_, rt);
  out.tag_in_view.assign(spec_.cols * spec_.rows, false);
  for (int tag = 0; tag < spec_.cols * spec_.rows && !out.truth.empty(); ++tag) {
    bool inside = true;
    for (int k = 0; k < 4; ++k) inside &= Inside(out.truth[tag * 4 + k], lens_);
    out.tag_in_view[tag] = inside;
  }
  return out;
}

std::vector<std::array<double, 6>> WholeBoardPoses(const BoardSpec& spec, const SyntheticLens& lens,
                                                   int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  const Eigen::Vector2d size = PatternSize_m(spec);
  const Eigen::Vector3d board_centre(size.x() / 2, size.y() / 2, 0);
  const double board_m = size.maxCoeff();
  const double focal = lens.intrinsics[0];
  std::vector<std::array<double, 6>> poses;
  for (int attempt = 0; attempt < 200000 && static_cast<int>(poses.size()) < count; ++attempt) {
    // Target pixel of the board's centre: anywhere on the imager, borders favoured.
    const double a = unit(rng), b = unit(rng);
    const Eigen::Vector2d target(lens.width * (0.5 + 0.5 * std::cbrt(2 * a - 1) * 0.95),
                                 lens.height * (0.5 + 0.5 * std::cbrt(2 * b - 1) * 0.95));
    std::vector<Eigen::Vector3d> ray;
    if (!UnprojectPixels(lens.lensmodel, lens.intrinsics, {target}, &ray)) continue;
    // Board spanning 250..600 px at the centre of the imager.
    const double span_px = 250 + 350 * unit(rng);
    const double distance = focal * board_m / span_px;
    const double tilt = 40 * M_PI / 180 * std::sqrt(unit(rng)), axis = 2 * M_PI * unit(rng);
    const double roll = (unit(rng) - 0.5) * 0.6;
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(tilt, Eigen::Vector3d(std::cos(axis), std::sin(axis), 0)) *
         Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()))  // upright: board +y is up
            .toRotationMatrix();
    const Eigen::Vector3d centre_in_cam = ray[0].normalized() * distance;
    const Eigen::Vector3d t = centre_in_cam - R * board_centre;
    const Eigen::AngleAxisd aa(R);
    const Eigen::Vector3d r = aa.axis() * aa.angle();
    const std::array<double, 6> rt = {r.x(), r.y(), r.z(), t.x(), t.y(), t.z()};
    const std::vector<Eigen::Vector2d> q = ProjectCorners(spec, lens, rt);
    bool inside = !q.empty();
    for (const Eigen::Vector2d& p : q) inside &= Inside(p, lens);
    if (inside) poses.push_back(rt);
  }
  return poses;
}

}  // namespace fresco::calib
