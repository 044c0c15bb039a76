#include "pipeline/paint/refine_anchor.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace fresco {
namespace {

constexpr double kSmoothTiles = 1.0;  // the field's smoothing (Gaussian sigma), tiles

cv::Point2d Apply(const cv::Matx33d& H, double x, double y) {
  const cv::Vec3d q = H * cv::Vec3d(x, y, 1);
  return {q[0] / q[2], q[1] / q[2]};
}

// Texel position of tile (tx, ty)'s centre.
cv::Point2d TileCentre(int tx, int ty) {
  return {(tx + 0.5) * kAnchorTileTexels - 0.5, (ty + 0.5) * kAnchorTileTexels - 0.5};
}

// The texel-resolution field (CV_32FC2, `size`) from per-tile values (tile centres exact).
cv::Mat UpsampleField(const cv::Mat& tiles, const cv::Size& size) {
  cv::Mat tiles32, full;
  tiles.convertTo(tiles32, CV_32FC2);
  cv::resize(tiles32, full, cv::Size(tiles.cols, tiles.rows) * kAnchorTileTexels, 0, 0,
             cv::INTER_LINEAR);
  return full(cv::Rect(0, 0, size.width, size.height)).clone();
}

// Absolute sampling maps for remap: q -> q + field(q).
void Maps(const cv::Mat& field, cv::Mat* map) {
  map->create(field.size(), CV_32FC2);
  for (int y = 0; y < field.rows; ++y) {
    const cv::Vec2f* f = field.ptr<cv::Vec2f>(y);
    cv::Vec2f* m = map->ptr<cv::Vec2f>(y);
    for (int x = 0; x < field.cols; ++x) m[x] = cv::Vec2f(x + f[x][0], y + f[x][1]);
  }
}

}  // namespace

void InitRefineAnchor(const BaseBuffer& buffer, RefineAnchor* anchor) {
  const cv::Size tiles((buffer.width + kAnchorTileTexels - 1) / kAnchorTileTexels,
                       (buffer.height + kAnchorTileTexels - 1) / kAnchorTileTexels);
  *anchor = RefineAnchor();
  anchor->sum = cv::Mat::zeros(tiles, CV_64FC2);
  anchor->count = cv::Mat::zeros(tiles, CV_64F);
  anchor->background_pending = cv::Mat::zeros(tiles, CV_64FC2);
}

bool TakeBackgroundMove(RefineAnchor* anchor, cv::Mat* field) {
  double largest = 0;
  cv::minMaxLoc(anchor->background_pending.reshape(1), nullptr, &largest);
  double smallest = 0;
  cv::minMaxLoc(anchor->background_pending.reshape(1), &smallest);
  if (std::max(largest, -smallest) < 0.5) return false;
  *field = UpsampleField(anchor->background_pending,
                         anchor->background_pending.size() * kAnchorTileTexels);
  anchor->background_pending.setTo(0);
  return true;
}

double LargestDisplacement(const cv::Matx33d& H, const cv::Rect& region) {
  double largest = 0;
  for (int c = 0; c < 4; ++c) {
    const double x = (c & 1) ? region.br().x : region.x, y = (c & 2) ? region.br().y : region.y;
    largest = std::max(largest, cv::norm(Apply(H, x, y) - cv::Point2d(x, y)));
  }
  return largest;
}

bool AddAnchorSample(const cv::Matx33d& buffer_from_warped, const cv::Rect& region,
                     const RefineOptions& options, RefineAnchor* anchor, cv::Mat* field) {
  ++anchor->samples;
  double largest_mean = 0;
  for (int ty = 0; ty < anchor->count.rows; ++ty) {
    for (int tx = 0; tx < anchor->count.cols; ++tx) {
      const cv::Point2d c = TileCentre(tx, ty);
      if (c.x < region.x || c.y < region.y || c.x >= region.br().x || c.y >= region.br().y)
        continue;
      const cv::Point2d d = Apply(buffer_from_warped, c.x, c.y) - c;
      cv::Vec2d& s = anchor->sum.at<cv::Vec2d>(ty, tx);
      double& n = anchor->count.at<double>(ty, tx);
      s += cv::Vec2d(d.x, d.y);
      n += 1;
      if (n >= options.anchor_min_frames) largest_mean = std::max(largest_mean, cv::norm(s) / n);
    }
  }
  if (!(largest_mean > options.anchor_step_px)) return false;

  // The mean field where frames asked, smoothed (normalised convolution) and extended a
  // little beyond; zero far from any sample.
  cv::Mat sum_smooth, count_smooth;
  cv::GaussianBlur(anchor->sum, sum_smooth, cv::Size(), kSmoothTiles, kSmoothTiles,
                   cv::BORDER_REPLICATE);
  cv::GaussianBlur(anchor->count, count_smooth, cv::Size(), kSmoothTiles, kSmoothTiles,
                   cv::BORDER_REPLICATE);
  cv::Mat tiles(anchor->count.size(), CV_64FC2, cv::Scalar(0, 0));
  for (int ty = 0; ty < tiles.rows; ++ty) {
    for (int tx = 0; tx < tiles.cols; ++tx) {
      const double n = count_smooth.at<double>(ty, tx);
      if (n < 0.05) continue;
      const cv::Vec2d f = sum_smooth.at<cv::Vec2d>(ty, tx) / n;
      tiles.at<cv::Vec2d>(ty, tx) = f;
      largest_mean = std::max(largest_mean, cv::norm(f));
      // Re-expressed in the moved buffer: each sample there loses the move.
      anchor->sum.at<cv::Vec2d>(ty, tx) -= anchor->count.at<double>(ty, tx) * f;
    }
  }
  anchor->background_pending += tiles;
  *field = UpsampleField(tiles, cv::Size(anchor->count.cols * kAnchorTileTexels,
                                         anchor->count.rows * kAnchorTileTexels));
  ++anchor->moves;
  anchor->largest_move_px = std::max(anchor->largest_move_px, largest_mean);
  return true;
}

void MovePaintedBuffer(const cv::Mat& field_full, const BaseBuffer& buffer,
                       PaintedBuffer* painted) {
  const cv::Mat field = field_full(cv::Rect(0, 0, buffer.width, buffer.height));
  cv::Mat map, bgra, alpha_source, alpha, quality;
  Maps(field, &map);
  cv::remap(painted->bgra, bgra, map, cv::noArray(), cv::INTER_CUBIC, cv::BORDER_REPLICATE);
  cv::extractChannel(painted->bgra, alpha_source, 3);
  cv::remap(alpha_source, alpha, map, cv::noArray(), cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  // A texel next to an unpainted one would have blended white into its colour: unpainted.
  cv::erode(alpha, alpha, cv::Mat());
  cv::insertChannel(alpha, bgra, 3);
  painted->bgra = bgra;
  // What moved was painted in a worse gauge: any later frame may replace it.
  painted->quality.setTo(0);
  int surface = 0;
  for (int k = 0; k < buffer.NumTexels(); ++k)
    surface += buffer.on_surface[k] && alpha.data[buffer.texel_index[k]] != 0;
  painted->painted_surface_texels = surface;
}

void MoveWarpedImages(const cv::Mat& field_full, cv::Mat* bgr, cv::Mat* valid,
                      cv::Mat* quality) {
  const cv::Mat field = field_full(cv::Rect(0, 0, bgr->cols, bgr->rows));
  cv::Mat map, out_bgr, out_valid, out_quality;
  Maps(field, &map);
  cv::remap(*bgr, out_bgr, map, cv::noArray(), cv::INTER_CUBIC, cv::BORDER_REPLICATE);
  cv::remap(*valid, out_valid, map, cv::noArray(), cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  cv::remap(*quality, out_quality, map, cv::noArray(), cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  cv::erode(out_valid, out_valid, cv::Mat());
  *bgr = out_bgr;
  *valid = out_valid;
  *quality = out_quality;
}

}  // namespace fresco
