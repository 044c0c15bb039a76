// Board detection in one image: per-corner pixel observations with their corner ids
// (calib/board.h), partial boards included. AprilGrid: the apriltag library (tag36h11), then
// optionally cv::cornerSubPix on each tag corner. Chessboard: OpenCV's
// findChessboardCornersSB, falling back to findChessboardCorners + cornerSubPix.
// Pixel convention: (0,0) is the centre of the top-left pixel (apriltag, OpenCV and mrcal).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "calib/board.h"

namespace fresco::calib {

struct CornerObservation {
  int id = 0;             // corner id on the board (calib/board.h)
  Eigen::Vector2d pixel;  // (0,0) = centre of the top-left pixel
};

struct BoardDetection {
  bool found = false;
  std::string reason;  // why not found (one line), empty when found
  std::vector<CornerObservation> corners;
  int tags = 0;        // AprilGrid: tags kept
};

struct DetectOptions {
  // AprilGrid: refine each tag corner with cv::cornerSubPix (window scaled to the tag size).
  bool refine_tag_corners = true;
  double quad_decimate = 1.0;  // apriltag: 1 keeps full resolution (small tags need it)
  int max_hamming = 1;         // apriltag: bit errors accepted per tag
  int min_corners = 8;         // fewer than this: not found
};

// `gray` is CV_8U.
BoardDetection DetectBoard(const cv::Mat& gray, const BoardSpec& spec,
                           const DetectOptions& options = {});

}  // namespace fresco::calib
