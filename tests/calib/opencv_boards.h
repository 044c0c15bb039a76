// An AprilGrid drawn and photographed by OpenCV alone, for testing the detector on boards it
// was not made with (issue 56): each tag is OpenCV's aruco DICT_APRILTAG_36h11 marker
// (cv::aruco::drawMarker, a black border of 1 or 2 bits), laid out as Kalibr's AprilGrid
// (tag id row-major from the bottom-left, +x right, +y up, corner k of a tag at its
// bottom-left, bottom-right, top-right, top-left: calib/board.h), with no black squares
// where the gaps cross, on white paper with a margin of any width. The board is seen through
// an OpenCV lens (k1, k2, p1, p2: mrcal's LENSMODEL_OPENCV4) from a known pose: cv::remap
// with rays from cv::undistortPoints, 2 x 2 samples per pixel, over a dark or light
// surround; then optional vignetting, blur, grey noise, a tone curve (contrast, gamma) and
// JPEG. The true pixel of every corner comes
// from cv::projectPoints. Nothing of Fresco's own renderer (calib/sample_views.h) is used.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace fresco::calib::testing {

struct ElsewhereLens {
  // fx, fy, cx, cy, k1, k2, p1, p2 (OpenCV's and mrcal's LENSMODEL_OPENCV4)
  std::vector<double> intrinsics = {500, 500, 511.5, 383.5, -0.28, 0.09, 0, 0};
  int width = 1024, height = 768;
};

struct ElsewhereBoard {
  int cols = 6, rows = 6;
  double tag_m = 0.088;         // the black square's edge
  double spacing = 0.3;         // gap / tag edge
  int border_bits = 2;          // Kalibr prints 2; OpenCV's and apriltag's own tags have 1
  double margin_tags = 0.5;     // white paper beyond the outer tags, in tag edges
  int black = 25, white = 235;  // printed grey levels
};

struct ElsewhereShot {
  int surround = 20;         // grey level beyond the paper
  double blur_sigma_px = 0;  // Gaussian blur (0: none)
  double noise_grey = 2;     // Gaussian noise sigma, grey levels
  int jpeg_quality = 0;      // 0: no JPEG round trip
  unsigned seed = 1;         // the noise
  // Light falling off towards the imager's corners (optical, before blur and noise): the
  // grey times 1 - vignette * (r / r_corner)^2, r from the imager's centre.
  double vignette = 0;
  // The camera's tone curve (after noise, before JPEG): the grey about mid-grey 128 times
  // `contrast`, then 255 * (grey / 255)^gamma.
  double contrast = 1;
  double gamma = 1;
};

struct ElsewhereView {
  cv::Mat gray;                        // CV_8U, lens width x height
  std::array<double, 6> rt{};          // cam_from_board: Rodrigues r, then t
  std::vector<Eigen::Vector2d> truth;  // (cols * rows * 4) true pixel of every corner id
};

class ElsewhereRenderer {
 public:
  ElsewhereRenderer(const ElsewhereBoard& board, const ElsewhereLens& lens);
  ElsewhereView Render(const std::array<double, 6>& rt, const ElsewhereShot& shot) const;
  // Corner id (tag * 4 + k) on the board, metres, z = 0.
  Eigen::Vector3d Corner(int id) const;
  // `count` poses of the whole board (its paper margin included) in view, centres pushed
  // towards the imager's edges and corners in most of them, tilted up to 45 deg.
  std::vector<std::array<double, 6>> Poses(int count, unsigned seed) const;
  const cv::Mat& texture() const { return texture_; }

 private:
  bool PaperInside(const std::array<double, 6>& rt) const;
  ElsewhereBoard board_;
  ElsewhereLens lens_;
  cv::Mat texture_;      // the printed board, paper margin included
  double px_per_m_ = 0;  // texture pixels per board metre
  double margin_m_ = 0;
  std::vector<cv::Point3f> rays_;  // (2 height, 2 width) one per sample, z = 1
};

// OpenCV's aruco on `gray` with its default parameters (markerBorderBits set to the board's):
// ids < num_ids read, the reference of issue 56's targets.
std::vector<int> ArucoIdsDefault(const cv::Mat& gray, int num_ids, int border_bits);

}  // namespace fresco::calib::testing
