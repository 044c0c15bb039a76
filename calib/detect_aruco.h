// OpenCV's aruco detector (DICT_APRILTAG_36h11) on AprilGrid tags: Kalibr prints them with a
// 2-bit black border, OpenCV (GridBoard, drawMarker) and the apriltag library's own images
// with 1 bit: the second detector of calib/detect.cc. Its corners come back in the apriltag
// library's order (p[0] bottom-left, p[1] bottom-right, p[2] top-right, p[3] top-left of the
// black square on the upright tag; aruco itself starts at the bottom-right), unrefined.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace fresco::calib {

struct TagQuad {
  int id = 0;
  std::array<Eigen::Vector2d, 4> p;  // apriltag order, (0,0) = centre of the top-left pixel
  int border_bits = 2;               // the black border the tag was read with (1 or 2)
};

// Tags with ids < `num_ids` and a black border `border_bits` wide. `gray` is CV_8U.
std::vector<TagQuad> DetectTagsAruco(const cv::Mat& gray, int num_ids, int border_bits = 2);

// aruco's corner k is the apriltag library's corner kArucoToApriltag[k].
extern const int kArucoToApriltag[4];

}  // namespace fresco::calib
