#include "tests/calib/opencv_boards.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <stdexcept>

#include <Eigen/Dense>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace fresco::calib::testing {
namespace {

constexpr int kSamples = 2;        // per pixel and axis
constexpr int kTagPx = 80;         // the black square in the texture
constexpr int kOutlineSteps = 16;  // points per paper edge checked to be in view
constexpr double kInsidePx = 2;
constexpr double kMaxObliqueDeg = 55;
constexpr double kMinSpanPx = 150;

cv::Matx33d CameraMatrix(const ElsewhereLens& lens) {
  const std::vector<double>& p = lens.intrinsics;
  return cv::Matx33d(p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
}

std::vector<double> Distortion(const ElsewhereLens& lens) {
  return {lens.intrinsics.begin() + 4, lens.intrinsics.end()};
}

cv::Matx33d Rotation(const std::array<double, 6>& rt) {
  cv::Matx33d r;
  cv::Rodrigues(cv::Vec3d(rt[0], rt[1], rt[2]), r);
  return r;
}

// The point (x, y) on the plane z = 1 that the OpenCV4 lens `q` (fx, fy, cx, cy, k1, k2, p1,
// p2) distorts to `d` (normalised): Newton's method from d. (cv::undistortPoints iterated to
// the same precision took 3 s for the 3.1 M samples of a view; this lens's radial map is
// monotonic over the imager, so Newton's method converges from d.)
Eigen::Vector2d Undistort(const std::vector<double>& q, const Eigen::Vector2d& d) {
  const double k1 = q[4], k2 = q[5], p1 = q[6], p2 = q[7];
  Eigen::Vector2d p = d;
  for (int it = 0; it < 50; ++it) {
    const double x = p.x(), y = p.y(), r2 = x * x + y * y;
    const double radial = 1 + k1 * r2 + k2 * r2 * r2, dradial = k1 + 2 * k2 * r2;
    const Eigen::Vector2d f(x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x) - d.x(),
                            y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y - d.y());
    Eigen::Matrix2d jacobian;
    jacobian << radial + 2 * x * x * dradial + 2 * p1 * y + 6 * p2 * x,
        2 * x * y * dradial + 2 * p1 * x + 2 * p2 * y,
        2 * x * y * dradial + 2 * p1 * x + 2 * p2 * y,
        radial + 2 * y * y * dradial + 6 * p1 * y + 2 * p2 * x;
    const Eigen::Vector2d step = jacobian.inverse() * f;
    p -= step;
    if (step.squaredNorm() < 1e-26) break;
  }
  return p;
}

}  // namespace

ElsewhereRenderer::ElsewhereRenderer(const ElsewhereBoard& board, const ElsewhereLens& lens)
    : board_(board), lens_(lens) {
  const int bits = 6 + 2 * board.border_bits;
  if (kTagPx % bits != 0) throw std::invalid_argument("border_bits must be 1 or 2");
  const double gap = board.spacing * kTagPx;
  if (std::abs(gap - std::round(gap)) > 1e-9) throw std::invalid_argument("spacing * 80 not whole");
  const int gap_px = static_cast<int>(std::lround(gap)), pitch_px = kTagPx + gap_px;
  const int margin_px = static_cast<int>(std::lround(board.margin_tags * kTagPx));
  px_per_m_ = kTagPx / board.tag_m;
  margin_m_ = margin_px / px_per_m_;
  const int w = board.cols * pitch_px - gap_px + 2 * margin_px;
  const int h = board.rows * pitch_px - gap_px + 2 * margin_px;
  texture_ = cv::Mat(h, w, CV_8U, cv::Scalar(board.white));
  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  for (int id = 0; id < board.cols * board.rows; ++id) {
    cv::Mat marker;
    cv::aruco::drawMarker(dictionary, id, kTagPx, marker, board.border_bits);
    // OpenCV draws the apriltag family's tag turned by 180 degrees (its corner 0, top-left,
    // is the library's bottom-right): turned back, the tag stands as Kalibr prints it.
    cv::rotate(marker, marker, cv::ROTATE_180);
    marker.convertTo(marker, CV_8U, (board.white - board.black) / 255.0, board.black);
    const int col = id % board.cols, row = id / board.cols;  // row 0 at the bottom
    marker.copyTo(
        texture_(cv::Rect(margin_px + col * pitch_px, margin_px + (board.rows - 1 - row) * pitch_px,
                          kTagPx, kTagPx)));
  }
  rays_.reserve(static_cast<size_t>(kSamples * kSamples) * lens.width * lens.height);
  const std::vector<double>& q = lens.intrinsics;
  for (int j = 0; j < kSamples * lens.height; ++j)
    for (int i = 0; i < kSamples * lens.width; ++i) {
      const Eigen::Vector2d n =
          Undistort(q, Eigen::Vector2d(((i + 0.5) / kSamples - 0.5 - q[2]) / q[0],
                                       ((j + 0.5) / kSamples - 0.5 - q[3]) / q[1]));
      rays_.emplace_back(static_cast<float>(n.x()), static_cast<float>(n.y()), 1.f);
    }
}

Eigen::Vector3d ElsewhereRenderer::Corner(int id) const {
  const int tag = id / 4, k = id % 4;
  const double pitch = board_.tag_m * (1 + board_.spacing);
  return Eigen::Vector3d((tag % board_.cols) * pitch + ((k == 1 || k == 2) ? board_.tag_m : 0),
                         (tag / board_.cols) * pitch + ((k == 2 || k == 3) ? board_.tag_m : 0), 0);
}

ElsewhereView ElsewhereRenderer::Render(const std::array<double, 6>& rt,
                                        const ElsewhereShot& shot) const {
  ElsewhereView out;
  out.rt = rt;
  const cv::Matx33d r = Rotation(rt);
  const cv::Vec3d t(rt[3], rt[4], rt[5]);
  const cv::Vec3d normal(r(0, 2), r(1, 2), r(2, 2));
  const double pattern_h_m =
      board_.rows * board_.tag_m * (1 + board_.spacing) - board_.spacing * board_.tag_m;
  const int w = kSamples * lens_.width, h = kSamples * lens_.height;
  // One (u, v) texture position per sample; off the board's plane: far outside the texture.
  cv::Mat_<cv::Vec2f> map(h, w, cv::Vec2f(-1e6f, -1e6f));
  const double n_t = normal.dot(t);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const cv::Point3f& ray = rays_[static_cast<size_t>(j) * w + i];
      const cv::Vec3d d(ray.x, ray.y, ray.z);
      const double s = n_t / normal.dot(d);
      if (!std::isfinite(s) || s <= 0) continue;
      const cv::Vec3d b = r.t() * (s * d - t);
      map(j, i) = cv::Vec2f(static_cast<float>((b[0] + margin_m_) * px_per_m_ - 0.5),
                            static_cast<float>((margin_m_ + pattern_h_m - b[1]) * px_per_m_ - 0.5));
    }
  cv::Mat fine;
  cv::remap(texture_, fine, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::Scalar(shot.surround));
  cv::resize(fine, out.gray, cv::Size(lens_.width, lens_.height), 0, 0, cv::INTER_AREA);
  if (shot.vignette > 0) {
    const double cx = 0.5 * (lens_.width - 1), cy = 0.5 * (lens_.height - 1);
    const double corner_sq = cx * cx + cy * cy;
    for (int j = 0; j < out.gray.rows; ++j)
      for (int i = 0; i < out.gray.cols; ++i) {
        const double r_sq = ((i - cx) * (i - cx) + (j - cy) * (j - cy)) / corner_sq;
        uchar& g = out.gray.at<uchar>(j, i);
        g = cv::saturate_cast<uchar>(g * (1 - shot.vignette * r_sq));
      }
  }
  if (shot.blur_sigma_px > 0)
    cv::GaussianBlur(out.gray, out.gray, cv::Size(0, 0), shot.blur_sigma_px);
  if (shot.noise_grey > 0) {  // whole grey levels, saturated
    cv::Mat_<int16_t> noise(out.gray.size());
    cv::RNG(shot.seed).fill(noise, cv::RNG::NORMAL, 0, shot.noise_grey);
    cv::add(out.gray, noise, out.gray, cv::noArray(), CV_8U);
  }
  if (shot.contrast != 1 || shot.gamma != 1) {
    cv::Mat_<uchar> curve(1, 256);
    for (int g = 0; g < 256; ++g) {
      const double c = std::clamp(128 + shot.contrast * (g - 128), 0.0, 255.0);
      curve(0, g) = cv::saturate_cast<uchar>(255 * std::pow(c / 255, shot.gamma));
    }
    cv::LUT(out.gray, curve, out.gray);
  }
  if (shot.jpeg_quality > 0) {
    std::vector<uchar> bytes;
    cv::imencode(".jpg", out.gray, bytes, {cv::IMWRITE_JPEG_QUALITY, shot.jpeg_quality});
    out.gray = cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
  }
  std::vector<cv::Point3d> corners;
  for (int id = 0; id < board_.cols * board_.rows * 4; ++id) {
    const Eigen::Vector3d c = Corner(id);
    corners.emplace_back(c.x(), c.y(), c.z());
  }
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(corners, cv::Vec3d(rt[0], rt[1], rt[2]), t, CameraMatrix(lens_),
                    Distortion(lens_), pixels);
  for (const cv::Point2d& p : pixels) out.truth.emplace_back(p.x, p.y);
  return out;
}

bool ElsewhereRenderer::PaperInside(const std::array<double, 6>& rt) const {
  const double pitch = board_.tag_m * (1 + board_.spacing);
  const double x0 = -margin_m_, y0 = -margin_m_;
  const double x1 = board_.cols * pitch - board_.spacing * board_.tag_m + margin_m_;
  const double y1 = board_.rows * pitch - board_.spacing * board_.tag_m + margin_m_;
  std::vector<cv::Point3d> outline;
  for (int s = 0; s < kOutlineSteps; ++s) {
    const double a = static_cast<double>(s) / kOutlineSteps;
    outline.emplace_back(x0 + a * (x1 - x0), y0, 0);
    outline.emplace_back(x1, y0 + a * (y1 - y0), 0);
    outline.emplace_back(x1 - a * (x1 - x0), y1, 0);
    outline.emplace_back(x0, y1 - a * (y1 - y0), 0);
  }
  const cv::Matx33d r = Rotation(rt);
  const cv::Vec3d t(rt[3], rt[4], rt[5]);
  for (const cv::Point3d& p : outline) {
    const cv::Vec3d c = r * cv::Vec3d(p.x, p.y, p.z) + t;
    // Rays more than 60 degrees off the axis lie beyond this lens's imager (and where its
    // polynomial no longer describes it).
    if (c[2] <= 0 || std::hypot(c[0], c[1]) > 1.7 * c[2]) return false;
  }
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(outline, cv::Vec3d(rt[0], rt[1], rt[2]), t, CameraMatrix(lens_),
                    Distortion(lens_), pixels);
  return std::all_of(pixels.begin(), pixels.end(), [&](const cv::Point2d& p) {
    return p.x >= kInsidePx && p.y >= kInsidePx && p.x <= lens_.width - 1 - kInsidePx &&
           p.y <= lens_.height - 1 - kInsidePx;
  });
}

std::vector<std::array<double, 6>> ElsewhereRenderer::Poses(int count, unsigned seed) const {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  const double pitch = board_.tag_m * (1 + board_.spacing);
  const cv::Vec3d centre(0.5 * (board_.cols * pitch - board_.spacing * board_.tag_m),
                         0.5 * (board_.rows * pitch - board_.spacing * board_.tag_m), 0);
  std::vector<std::array<double, 6>> poses;
  for (int attempt = 0; attempt < 100000 && static_cast<int>(poses.size()) < count; ++attempt) {
    const double distance = 0.75 + 0.7 * unit(rng);
    const double tilt = 45 * M_PI / 180 * std::sqrt(unit(rng)), axis = 2 * M_PI * unit(rng);
    const double roll = (unit(rng) - 0.5) * 0.6;
    cv::Matx33d upright, tilted, rolled;  // upright: the board's +y up the image
    cv::Rodrigues(cv::Vec3d(M_PI, 0, 0), upright);
    cv::Rodrigues(cv::Vec3d(std::cos(axis), std::sin(axis), 0) * tilt, tilted);
    cv::Rodrigues(cv::Vec3d(0, 0, roll), rolled);
    const cv::Matx33d r = rolled * tilted * upright;
    cv::Vec3d rvec;
    cv::Rodrigues(r, rvec);
    // The board's centre moved from the optical axis along `direction` as far as the paper
    // stays in view (three in four views), or part of the way.
    const double direction = 2 * M_PI * unit(rng);
    const bool to_edge = unit(rng) < 0.75;
    const auto pose_at = [&](double s) {
      const cv::Vec3d c(s * 1.6 * std::cos(direction) * distance,
                        s * 1.2 * std::sin(direction) * distance, distance);
      const cv::Vec3d t = c - r * centre;
      return std::array<double, 6>{rvec[0], rvec[1], rvec[2], t[0], t[1], t[2]};
    };
    if (!PaperInside(pose_at(0))) continue;
    double lo = 0, hi = 1;
    for (int i = 0; i < 30; ++i) {
      const double mid = 0.5 * (lo + hi);
      (PaperInside(pose_at(mid)) ? lo : hi) = mid;
    }
    const std::array<double, 6> rt = pose_at(to_edge ? 0.98 * lo : unit(rng) * lo);
    // Seen from the camera the board is tilted at most kMaxObliqueDeg from facing it, and its
    // pattern spans at least kMinSpanPx each way (a board the operator would keep).
    const cv::Vec3d c = r * centre + cv::Vec3d(rt[3], rt[4], rt[5]);
    const cv::Vec3d normal(r(0, 2), r(1, 2), r(2, 2));
    if (std::abs(normal.dot(c)) / cv::norm(c) < std::cos(kMaxObliqueDeg * M_PI / 180)) continue;
    std::vector<cv::Point3d> pattern;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d p = Corner((k == 0   ? 0
                                        : k == 1 ? board_.cols - 1
                                        : k == 2 ? board_.cols * board_.rows - 1
                                                 : board_.cols * (board_.rows - 1)) *
                                           4 +
                                       k);
      pattern.emplace_back(p.x(), p.y(), 0);
    }
    std::vector<cv::Point2d> q;
    cv::projectPoints(pattern, rvec, cv::Vec3d(rt[3], rt[4], rt[5]), CameraMatrix(lens_),
                      Distortion(lens_), q);
    const cv::Rect2d box = cv::boundingRect(std::vector<cv::Point2f>(q.begin(), q.end()));
    if (std::min(box.width, box.height) < kMinSpanPx) continue;
    poses.push_back(rt);
  }
  return poses;
}

std::vector<int> ArucoIdsDefault(const cv::Mat& gray, int num_ids, int border_bits) {
  cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
  params->markerBorderBits = border_bits;
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<int> ids;
  cv::aruco::detectMarkers(gray, cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11),
                           corners, ids, params);
  std::set<int> unique;
  for (int id : ids)
    if (id >= 0 && id < num_ids) unique.insert(id);
  return {unique.begin(), unique.end()};
}

}  // namespace fresco::calib::testing
