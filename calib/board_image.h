// A printable image of a board: AprilGrid tags come from the apriltag library's own
// tag36h11 family (apriltag_to_image), chessboards are drawn square by square. The pattern
// is drawn at a whole number of pixels per tag bit (or per square) for the given DPI; the
// physical size of what is drawn is reported (and written below the pattern), so that a
// print at 100 % scale can be checked with a ruler against the spec.
#pragma once

#include <string>

#include <opencv2/core.hpp>

#include "calib/board.h"

namespace fresco::calib {

struct BoardImage {
  cv::Mat gray;                 // CV_8U, white background, label strip at the bottom
  double dpi = 0;
  double pattern_width_m = 0;   // as drawn at `dpi` (may differ from the spec by < 1 px)
  double pattern_height_m = 0;
  double image_width_m = 0;     // the whole image at `dpi`
  double image_height_m = 0;
  double drawn_square_m = 0;    // tag edge or chessboard square as drawn
  double drawn_spacing = 0;     // AprilGrid gap/tag ratio as drawn
  std::string label;            // one line: spec, dpi and sizes
};

// Renders `spec` at `dpi` (72..1200). Fails when a tag bit or square would be < 2 pixels.
Status RenderBoardImage(const BoardSpec& spec, double dpi, BoardImage* image);

}  // namespace fresco::calib
