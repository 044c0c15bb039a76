// Synthetic calibration images (`fresco calib sample`, the detection tests): the printable
// board (calib/board_image.h) seen through a known lens model (mrcal projection) from a known board
// pose, anti-aliased (2 x 2 samples per pixel), optionally blurred and noisy, with the
// true pixel of every corner. Views of a whole board that sweep the imager (its borders and
// corners included, where a strong barrel distortion bends the tags most).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "calib/board.h"

namespace fresco::calib {

struct SyntheticLens {
  std::string lensmodel = "LENSMODEL_OPENCV4";
  // Strong barrel: the imager's corner sees a ray at 1.84 (normalised), where a pinhole
  // with the same focal length would put it at 1.33.
  std::vector<double> intrinsics = {480, 480, 511.5, 383.5, -0.25, 0.05, 0, 0};
  int width = 1024, height = 768;
};

struct SyntheticImageOptions {
  double blur_sigma_px = 0;  // Gaussian blur after rendering (0: none)
  double noise_px = 0;       // Gaussian noise sigma in grey levels
  int background = 90;       // grey level beyond the paper
  unsigned seed = 1;
};

struct SyntheticImage {
  cv::Mat gray;                        // CV_8U, lens.width x lens.height
  std::vector<Eigen::Vector2d> truth;  // (NumCorners) true pixel of every corner id
  std::vector<bool> tag_in_view;       // (cols * rows) all 4 corners >= 2 px inside
};

// Renders `spec` (an AprilGrid) at cam_from_board `rt` (Rodrigues r, then t).
class SyntheticImageRenderer {
 public:
  // kalibr_squares: the black squares Kalibr prints where the gaps between tags cross.
  SyntheticImageRenderer(const BoardSpec& spec, const SyntheticLens& lens,
                         bool kalibr_squares = true);
  SyntheticImage Render(const std::array<double, 6>& rt,
                        const SyntheticImageOptions& options) const;

 private:
  BoardSpec spec_;
  SyntheticLens lens_;
  cv::Mat texture_;                    // the board as printed (no label strip)
  double texture_px_per_m_ = 0;        // board metres -> texture pixels
  Eigen::Vector2d texture_origin_;     // texture pixel of board point (0, 0); +y is up
  std::vector<Eigen::Vector3d> rays_;  // (2 height, 2 width) one per sample
};

// `count` poses (cam_from_board) of the whole board in view, centres spread over the imager
// (borders and corners included), tilted up to ~40 deg.
std::vector<std::array<double, 6>> WholeBoardPoses(const BoardSpec& spec, const SyntheticLens& lens,
                                                   int count, unsigned seed);

}  // namespace fresco::calib
