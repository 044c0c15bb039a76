#include "calib/detect.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <apriltag/apriltag.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/kalibr_tag_family.h"

namespace fresco::calib {
namespace {

// cornerSubPix half-window for a chessboard: 40 % of the shortest distance between
// neighbouring corners (so the window holds one saddle), 3..11 px.
int ChessboardHalfWindow(const std::vector<cv::Point2f>& corners, const BoardSpec& spec) {
  double shortest = 1e9;
  for (int r = 0; r < spec.rows; ++r)
    for (int c = 0; c + 1 < spec.cols; ++c)
      shortest = std::min(shortest, static_cast<double>(cv::norm(corners[r * spec.cols + c + 1] -
                                                                 corners[r * spec.cols + c])));
  return std::clamp(static_cast<int>(0.4 * shortest), 3, 11);
}

// findChessboardCorners + cornerSubPix first (on opencv-chessboard-stereo it reproduces
// OpenCV's reference calibration; findChessboardCornersSB's corners moved fx by -0.8 %),
// findChessboardCornersSB when the classic detector fails.
BoardDetection DetectChessboard(const cv::Mat& gray, const BoardSpec& spec,
                                const DetectOptions& options) {
  BoardDetection out;
  const cv::Size pattern(spec.cols, spec.rows);
  std::vector<cv::Point2f> corners;
  bool found = cv::findChessboardCorners(
      gray, pattern, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
  if (found) {
    const int half = ChessboardHalfWindow(corners, spec);
    cv::cornerSubPix(gray, corners, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.01));
  } else {
    found = cv::findChessboardCornersSB(gray, pattern, corners,
                                        cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_ACCURACY);
  }
  if (!found) {
    out.reason = "chessboard " + std::to_string(spec.cols) + "x" + std::to_string(spec.rows) +
                 " not found (findChessboardCorners and findChessboardCornersSB)";
    return out;
  }
  for (size_t k = 0; k < corners.size(); ++k)
    out.corners.push_back({static_cast<int>(k), Eigen::Vector2d(corners[k].x, corners[k].y)});
  out.found = true;
  return out;
}

// Half-size of cornerSubPix's window for a tag: a quarter of its shortest edge in the image
// (so the window never reaches the next corner of the same tag), at least 2, at most 6.
int RefineHalfWindow(const apriltag_detection_t& det) {
  double shortest = 1e9;
  for (int k = 0; k < 4; ++k) {
    const double dx = det.p[(k + 1) % 4][0] - det.p[k][0], dy = det.p[(k + 1) % 4][1] - det.p[k][1];
    shortest = std::min(shortest, std::hypot(dx, dy));
  }
  return std::clamp(static_cast<int>(shortest / 8), 2, 6);
}

BoardDetection DetectAprilGrid(const cv::Mat& gray, const BoardSpec& spec,
                               const DetectOptions& options) {
  BoardDetection out;
  KalibrTagFamily family;
  apriltag_detector_t* detector = apriltag_detector_create();
  apriltag_detector_add_family_bits(detector, family.get(), options.max_hamming);
  detector->quad_decimate = static_cast<float>(options.quad_decimate);
  detector->nthreads = 1;
  detector->refine_edges = 1;
  cv::Mat contiguous = gray.isContinuous() ? gray : gray.clone();
  image_u8_t image = {contiguous.cols, contiguous.rows, static_cast<int32_t>(contiguous.step),
                      contiguous.data};
  zarray_t* detections = apriltag_detector_detect(detector, &image);
  std::map<int, int> count_by_id;
  std::vector<apriltag_detection_t> kept;
  for (int i = 0; i < zarray_size(detections); ++i) {
    apriltag_detection_t* det = nullptr;
    zarray_get(detections, i, &det);
    if (det->id >= spec.cols * spec.rows || det->hamming > options.max_hamming) continue;
    ++count_by_id[det->id];
    kept.push_back(*det);
  }
  for (const apriltag_detection_t& det : kept) {
    if (count_by_id[det.id] > 1) continue;  // the same id twice: trust neither
    std::vector<cv::Point2f> corners;
    for (int k = 0; k < 4; ++k)
      corners.emplace_back(static_cast<float>(det.p[k][0]), static_cast<float>(det.p[k][1]));
    if (options.refine_tag_corners) {
      const int half = RefineHalfWindow(det);
      cv::cornerSubPix(gray, corners, cv::Size(half, half), cv::Size(-1, -1),
                       cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 40, 1e-3));
    }
    for (int k = 0; k < 4; ++k)
      out.corners.push_back({det.id * 4 + k, Eigen::Vector2d(corners[k].x, corners[k].y)});
    ++out.tags;
  }
  apriltag_detections_destroy(detections);
  apriltag_detector_destroy(detector);
  std::sort(out.corners.begin(), out.corners.end(),
            [](const CornerObservation& a, const CornerObservation& b) { return a.id < b.id; });
  if (out.tags == 0) {
    out.corners.clear();
    out.reason = "no tag36h11 tag of the board (ids 0.." + std::to_string(spec.cols * spec.rows - 1) +
                 ") found";
  } else if (static_cast<int>(out.corners.size()) < options.min_corners) {
    out.reason = "only " + std::to_string(out.tags) + " tag(s) found (need " +
                 std::to_string((options.min_corners + 3) / 4) + ")";
    out.corners.clear();
  } else {
    out.found = true;
  }
  return out;
}

}  // namespace

BoardDetection DetectBoard(const cv::Mat& gray, const BoardSpec& spec,
                           const DetectOptions& options) {
  if (spec.kind == BoardKind::kChessboard) return DetectChessboard(gray, spec, options);
  return DetectAprilGrid(gray, spec, options);
}

}  // namespace fresco::calib
