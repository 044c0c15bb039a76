#include "calib/board_image.h"

#include <cmath>
#include <cstdio>

#include <apriltag/apriltag.h>
#include <opencv2/imgproc.hpp>

#include "calib/kalibr_tag_family.h"

namespace fresco::calib {
namespace {

constexpr double kMetresPerInch = 0.0254;
constexpr int kTagBlackBits = 10;  // Kalibr tag36h11: the black square is 10 bits wide

// Copies the family's bitmap of `id` (12 x 12 incl. its white bit border) scaled by
// `bit_px`, with its black square's top-left at (x0, y0).
void DrawTag(apriltag_family_t* family, int id, int bit_px, int x0, int y0, cv::Mat* gray) {
  image_u8_t* tag = apriltag_to_image(family, id);
  const int border = (static_cast<int>(family->total_width) - kTagBlackBits) / 2;
  for (int r = 0; r < tag->height; ++r)
    for (int c = 0; c < tag->width; ++c) {
      const uint8_t value = tag->buf[r * tag->stride + c];
      const cv::Rect cell(x0 + (c - border) * bit_px, y0 + (r - border) * bit_px, bit_px, bit_px);
      (*gray)(cell & cv::Rect(0, 0, gray->cols, gray->rows)).setTo(value);
    }
  image_u8_destroy(tag);
}

std::string Format(const char* format, double a, double b = 0, double c = 0) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), format, a, b, c);
  return buffer;
}

}  // namespace

Status RenderBoardImage(const BoardSpec& spec, double dpi, BoardImage* image) {
  if (!(dpi >= 72 && dpi <= 1200))
    return Status::Error("--dpi: must be 72..1200 (got " + Format("%g", dpi) + ")");
  const double px_per_m = dpi / kMetresPerInch;
  BoardImage out;
  out.dpi = dpi;
  int unit_px = 0, pattern_w = 0, pattern_h = 0, margin = 0;
  if (spec.kind == BoardKind::kAprilGrid) {
    unit_px = static_cast<int>(std::lround(spec.square_m / kTagBlackBits * px_per_m));
    if (unit_px < 2) return Status::Error("--dpi: a tag bit would be under 2 pixels; raise --dpi");
    const int tag_px = kTagBlackBits * unit_px;
    const int gap_px = static_cast<int>(std::lround(spec.spacing * tag_px));
    pattern_w = spec.cols * (tag_px + gap_px) - gap_px;
    pattern_h = spec.rows * (tag_px + gap_px) - gap_px;
    margin = 2 * unit_px + gap_px;
    out.drawn_square_m = tag_px / px_per_m;
    out.drawn_spacing = static_cast<double>(gap_px) / tag_px;
  } else {
    unit_px = static_cast<int>(std::lround(spec.square_m * px_per_m));
    if (unit_px < 2) return Status::Error("--dpi: a square would be under 2 pixels; raise --dpi");
    pattern_w = (spec.cols + 1) * unit_px;
    pattern_h = (spec.rows + 1) * unit_px;
    margin = unit_px;
    out.drawn_square_m = unit_px / px_per_m;
  }
  const int label_px = std::max(24, static_cast<int>(std::lround(0.008 * px_per_m)));
  const int width = pattern_w + 2 * margin, height = pattern_h + 2 * margin + label_px;
  out.gray = cv::Mat(height, width, CV_8U, cv::Scalar(255));
  if (spec.kind == BoardKind::kAprilGrid) {
    KalibrTagFamily kalibr;
    apriltag_family_t* family = kalibr.get();
    const int tag_px = kTagBlackBits * unit_px;
    const int pitch_px = tag_px + static_cast<int>(std::lround(spec.spacing * tag_px));
    if (spec.cols * spec.rows > static_cast<int>(family->ncodes)) {
      return Status::Error("--board: " + spec.text + " needs " + std::to_string(spec.cols * spec.rows) +
                           " tags; tag36h11 has " + std::to_string(family->ncodes));
    }
    for (int id = 0; id < spec.cols * spec.rows; ++id) {
      const int col = id % spec.cols, row = id / spec.cols;  // row 0 at the bottom (+y up)
      DrawTag(family, id, unit_px, margin + col * pitch_px,
              margin + (spec.rows - 1 - row) * pitch_px, &out.gray);
    }
  } else {
    for (int r = 0; r <= spec.rows; ++r)
      for (int c = 0; c <= spec.cols; ++c)
        if ((r + c) % 2 == 0)
          out.gray(cv::Rect(margin + c * unit_px, margin + r * unit_px, unit_px, unit_px))
              .setTo(0);
  }
  out.pattern_width_m = pattern_w / px_per_m;
  out.pattern_height_m = pattern_h / px_per_m;
  out.image_width_m = width / px_per_m;
  out.image_height_m = height / px_per_m;
  out.label = spec.text + Format("  at %g dpi, 100%% scale: pattern %.4f x %.4f m", dpi,
                                 out.pattern_width_m, out.pattern_height_m) +
              Format(spec.kind == BoardKind::kAprilGrid ? ", tag %.5f m" : ", square %.5f m",
                     out.drawn_square_m);
  const double scale = label_px / 40.0;
  cv::putText(out.gray, out.label, cv::Point(margin, height - label_px / 3), cv::FONT_HERSHEY_SIMPLEX,
              scale, cv::Scalar(0), std::max(1, static_cast<int>(scale * 1.5)), cv::LINE_AA);
  *image = out;
  return Status::Ok();
}

}  // namespace fresco::calib
