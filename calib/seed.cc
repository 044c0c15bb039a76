#include "calib/seed.h"

#include <cmath>
#include <cstring>
#include <string>

#include <opencv2/calib3d.hpp>

#include "calib/abandonable.h"

namespace fresco::calib {

namespace {

Status SeedHere(const std::vector<BoardView>& views, const BoardSpec& spec, int width, int height,
                CalibrationSeed* seed) {
  std::vector<std::vector<cv::Point3f>> object_points;
  std::vector<std::vector<cv::Point2f>> image_points;
  for (const BoardView& view : views) {
    if (view.corners.size() < 4)
      return Status::Error(view.name + ": only " + std::to_string(view.corners.size()) +
                           " corners: a board pose needs at least 4");
    auto& object = object_points.emplace_back();
    auto& image = image_points.emplace_back();
    for (const CornerObservation& c : view.corners) {
      const Eigen::Vector3d p = CornerPosition(spec, c.id);
      object.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.f);
      image.emplace_back(static_cast<float>(c.pixel.x()), static_cast<float>(c.pixel.y()));
    }
  }
  if (views.empty()) return Status::Error("no views to seed a calibration from");
  cv::Mat camera_matrix, distortion;
  std::vector<cv::Mat> rvecs, tvecs;
  const int flags = cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3;
  double rms = 0;
  try {
    rms = cv::calibrateCamera(object_points, image_points, cv::Size(width, height),
                              camera_matrix, distortion, rvecs, tvecs, flags);
  } catch (const cv::Exception& e) {
    return Status::Error(std::string("seeding with OpenCV calibrateCamera failed: ") + e.what());
  }
  CalibrationSeed out;
  out.fx = camera_matrix.at<double>(0, 0);
  out.fy = camera_matrix.at<double>(1, 1);
  out.cx = camera_matrix.at<double>(0, 2);
  out.cy = camera_matrix.at<double>(1, 2);
  out.k1 = distortion.at<double>(0);
  out.k2 = distortion.at<double>(1);
  out.rms_px = rms;
  for (size_t i = 0; i < rvecs.size(); ++i) {
    std::array<double, 6> rt;
    for (int k = 0; k < 3; ++k) {
      rt[k] = rvecs[i].at<double>(k);
      rt[3 + k] = tvecs[i].at<double>(k);
    }
    out.rt_cam_from_board.push_back(rt);
  }
  if (!(std::isfinite(out.fx) && out.fx > 0 && std::isfinite(out.fy) && out.fy > 0))
    return Status::Error("seeding with OpenCV calibrateCamera gave no usable focal length");
  *seed = out;
  return Status::Ok();
}

// A seed as bytes (a child process's sent back) and back.
std::string SeedBytes(const CalibrationSeed& seed) {
  std::string bytes;
  for (double v : {seed.fx, seed.fy, seed.cx, seed.cy, seed.k1, seed.k2, seed.rms_px})
    bytes.append(reinterpret_cast<const char*>(&v), sizeof(v));
  for (const std::array<double, 6>& rt : seed.rt_cam_from_board)
    bytes.append(reinterpret_cast<const char*>(rt.data()), sizeof(rt));
  return bytes;
}

bool SeedFromBytes(const std::string& bytes, CalibrationSeed* seed) {
  constexpr size_t kHead = 7 * sizeof(double);
  if (bytes.size() < kHead || (bytes.size() - kHead) % sizeof(std::array<double, 6>) != 0)
    return false;
  CalibrationSeed out;
  for (size_t i = 0;
       double* v : {&out.fx, &out.fy, &out.cx, &out.cy, &out.k1, &out.k2, &out.rms_px})
    std::memcpy(v, bytes.data() + sizeof(double) * i++, sizeof(double));
  out.rt_cam_from_board.resize((bytes.size() - kHead) / sizeof(std::array<double, 6>));
  std::memcpy(out.rt_cam_from_board.data(), bytes.data() + kHead, bytes.size() - kHead);
  *seed = out;
  return true;
}

}  // namespace

Status SeedCalibration(const std::vector<BoardView>& views, const BoardSpec& spec, int width,
                       int height, CalibrationSeed* seed, const std::function<bool()>& cancelled) {
  if (!cancelled) return SeedHere(views, spec, width, height, seed);
  if (cancelled()) return Status::Error("cancelled");
  std::string bytes;
  FRESCO_RETURN_IF_ERROR(RunAbandonably(
      "OpenCV calibrateCamera",
      [&](std::string* out) {
        CalibrationSeed here;
        const Status status = SeedHere(views, spec, width, height, &here);
        *out = status.ok() ? SeedBytes(here) : status.message();
        return status.ok();
      },
      cancelled, &bytes));
  if (!SeedFromBytes(bytes, seed))
    return Status::Error("OpenCV calibrateCamera: the process ended without its result");
  return Status::Ok();
}

}  // namespace fresco::calib
