#include "pipeline/paint/refine_anchor.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace fresco {
namespace {

constexpr double kSmoothTiles = 1.0;  // the field's smoothing (Gaussian sigma), tiles
constexpr double kReach = 0.05;       // smoothed sample weight below which nothing moves

cv::Point2d Apply(const cv::Matx33d& H, double x, double y) {
  const cv::Vec3d q = H * cv::Vec3d(x, y, 1);
  return {q[0] / q[2], q[1] / q[2]};
}

// Texel position of tile (tx, ty)'s centre.
cv::Point2d TileCentre(int tx, int ty) {
  return {(tx + 0.5) * kAnchorTileTexels - 0.5, (ty + 0.5) * kAnchorTileTexels - 0.5};
}

// The move for per-tile displacements `tiles` (CV_64FC2) that are non-zero only inside
// `tile_box`: upsampled to texels (bilinear between tile centres), within `buffer_size`.
AnchorMove MoveFromTiles(const cv::Mat& tiles, cv::Rect tile_box, const cv::Size& buffer_size) {
  // One tile of border so that the field fades to zero at the box's edge.
  tile_box = cv::Rect(tile_box.x - 1, tile_box.y - 1, tile_box.width + 2, tile_box.height + 2) &
             cv::Rect(0, 0, tiles.cols, tiles.rows);
  cv::Mat crop32, full;
  tiles(tile_box).convertTo(crop32, CV_32FC2);
  cv::resize(crop32, full, tile_box.size() * kAnchorTileTexels, 0, 0, cv::INTER_LINEAR);
  const cv::Rect texels(tile_box.tl() * kAnchorTileTexels, tile_box.size() * kAnchorTileTexels);
  AnchorMove move;
  move.roi = texels & cv::Rect(0, 0, buffer_size.width, buffer_size.height);
  move.field = full(move.roi - texels.tl()).clone();
  return move;
}

// Remapping a roi of buffer-sized images by a move, reading only the texels it needs.
struct MoveMap {
  cv::Rect roi;     // written
  cv::Rect source;  // read: roi grown by the largest displacement
  cv::Mat map;      // CV_32FC2, roi size: where in `source` each texel of roi comes from

  MoveMap(const AnchorMove& move, const cv::Rect& roi_in, const cv::Size& image) : roi(roi_in) {
    const cv::Mat field = move.field(roi - move.roi.tl());
    double low = 0, high = 0;
    cv::minMaxLoc(field.reshape(1), &low, &high);
    const double largest = std::max(high, -low);
    const int margin = static_cast<int>(std::ceil(largest)) + 3;  // + bicubic support
    source =
        cv::Rect(roi.x - margin, roi.y - margin, roi.width + 2 * margin, roi.height + 2 * margin) &
        cv::Rect(0, 0, image.width, image.height);
    map.create(roi.size(), CV_32FC2);
    const float dx = static_cast<float>(roi.x - source.x),
                dy = static_cast<float>(roi.y - source.y);
    for (int y = 0; y < roi.height; ++y) {
      const cv::Vec2f* f = field.ptr<cv::Vec2f>(y);
      cv::Vec2f* m = map.ptr<cv::Vec2f>(y);
      for (int x = 0; x < roi.width; ++x) m[x] = cv::Vec2f(dx + x + f[x][0], dy + y + f[x][1]);
    }
  }
  // The moved roi of `image` (not written back).
  cv::Mat Moved(const cv::Mat& image, int interpolation, int border) const {
    cv::Mat out;
    cv::remap(image(source), out, map, cv::noArray(), interpolation, border);
    return out;
  }
};

// Colours of the texels next to `alpha`'s (CV_8U) set ones carried into the unset ones, two
// texels deep, in place: bicubic interpolation reaches two texels, so a texel moved next to
// unpainted ones reads their extended colour instead of whatever they hold.
void ExtendColours(cv::Mat* bgra, const cv::Mat& alpha) {
  CV_Assert(bgra->type() == CV_8UC4 && alpha.type() == CV_8U && bgra->size() == alpha.size());
  cv::Mat set = alpha > 0;
  if (cv::countNonZero(set) == set.rows * set.cols) return;  // nothing unpainted
  for (int pass = 0; pass < 2; ++pass) {
    cv::Mat reached = set.clone();
    for (int y = 0; y < set.rows; ++y) {
      const uchar* s = set.ptr<uchar>(y);
      for (int x = 0; x < set.cols; ++x) {
        if (s[x]) continue;
        int sum[3] = {0, 0, 0}, n = 0;
        for (int dy = -1; dy <= 1; ++dy) {
          const int yy = y + dy;
          if (yy < 0 || yy >= set.rows) continue;
          const uchar* sn = set.ptr<uchar>(yy);
          const cv::Vec4b* cn = bgra->ptr<cv::Vec4b>(yy);
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx;
            if (xx < 0 || xx >= set.cols || !sn[xx]) continue;
            for (int c = 0; c < 3; ++c) sum[c] += cn[xx][c];
            ++n;
          }
        }
        if (n == 0) continue;
        cv::Vec4b& out = bgra->at<cv::Vec4b>(y, x);
        for (int c = 0; c < 3; ++c) out[c] = static_cast<uchar>((sum[c] + n / 2) / n);
        reached.at<uchar>(y, x) = 255;
      }
    }
    set = reached;
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
  anchor->surface = cv::Mat::zeros(buffer.height, buffer.width, CV_8U);
  for (int k = 0; k < buffer.NumTexels(); ++k)
    if (buffer.on_surface[k]) anchor->surface.data[buffer.texel_index[k]] = 255;
}

double LargestDisplacement(const cv::Matx33d& H, const cv::Rect& region) {
  double largest = 0;
  for (int c = 0; c < 4; ++c) {
    const double x = (c & 1) ? region.br().x : region.x, y = (c & 2) ? region.br().y : region.y;
    largest = std::max(largest, cv::norm(Apply(H, x, y) - cv::Point2d(x, y)));
  }
  return largest;
}

cv::Mat TilesAt(const RefineAnchor& anchor, const std::vector<cv::Point2f>& points) {
  cv::Mat tiles = cv::Mat::zeros(anchor.count.size(), CV_8U);
  for (const cv::Point2f& p : points) {
    const int tx = static_cast<int>(p.x) / kAnchorTileTexels;
    const int ty = static_cast<int>(p.y) / kAnchorTileTexels;
    if (tx >= 0 && ty >= 0 && tx < tiles.cols && ty < tiles.rows) tiles.at<uchar>(ty, tx) = 1;
  }
  return tiles;
}

cv::Mat TilesSet(const RefineAnchor& anchor, const cv::Mat& valid, const cv::Rect& box) {
  cv::Mat tiles = cv::Mat::zeros(anchor.count.size(), CV_8U);
  const cv::Rect within = box & cv::Rect(0, 0, valid.cols, valid.rows);
  for (int y = within.y; y < within.br().y; ++y) {
    const uchar* v = valid.ptr<uchar>(y);
    uchar* t = tiles.ptr<uchar>(y / kAnchorTileTexels);
    for (int x = within.x; x < within.br().x; ++x)
      if (v[x]) t[x / kAnchorTileTexels] = 1;
  }
  return tiles;
}

bool AddAnchorSample(const cv::Matx33d& buffer_from_warped, const cv::Mat& measured,
                     const cv::Mat& in_view, const RefineOptions& options, RefineAnchor* anchor,
                     AnchorMove* move) {
  ++anchor->samples;
  // Older samples fade (time constant anchor_window_frames): the buffer drifts a little
  // as registered frames paint over it, and old samples would not see that.
  const double keep =
      options.anchor_window_frames > 0 ? 1.0 - 1.0 / options.anchor_window_frames : 1.0;
  double largest_mean = 0;
  for (int ty = 0; ty < anchor->count.rows; ++ty) {
    for (int tx = 0; tx < anchor->count.cols; ++tx) {
      if (!measured.at<uchar>(ty, tx)) continue;
      const cv::Point2d c = TileCentre(tx, ty);
      const cv::Point2d d = Apply(buffer_from_warped, c.x, c.y) - c;
      cv::Vec2d& s = anchor->sum.at<cv::Vec2d>(ty, tx);
      double& n = anchor->count.at<double>(ty, tx);
      s = s * keep + cv::Vec2d(d.x, d.y);
      n = n * keep + 1;
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
  cv::Rect box;
  for (int ty = 0; ty < tiles.rows; ++ty) {
    for (int tx = 0; tx < tiles.cols; ++tx) {
      const double n = count_smooth.at<double>(ty, tx);
      if (n < kReach || !in_view.at<uchar>(ty, tx)) continue;
      const cv::Vec2d f = sum_smooth.at<cv::Vec2d>(ty, tx) / n;
      tiles.at<cv::Vec2d>(ty, tx) = f;
      box |= cv::Rect(tx, ty, 1, 1);
      largest_mean = std::max(largest_mean, cv::norm(f));
      // Re-expressed in the moved buffer: each sample d there becomes d - f.
      anchor->sum.at<cv::Vec2d>(ty, tx) -= anchor->count.at<double>(ty, tx) * f;
    }
  }
  anchor->background_pending += tiles;
  *move = MoveFromTiles(tiles, box, anchor->surface.size());
  ++anchor->moves;
  anchor->largest_move_px = std::max(anchor->largest_move_px, largest_mean);
  return true;
}

bool TakeBackgroundMove(RefineAnchor* anchor, AnchorMove* move) {
  cv::Rect box;
  bool due = false;
  for (int ty = 0; ty < anchor->background_pending.rows; ++ty) {
    for (int tx = 0; tx < anchor->background_pending.cols; ++tx) {
      const cv::Vec2d f = anchor->background_pending.at<cv::Vec2d>(ty, tx);
      if (f[0] == 0 && f[1] == 0) continue;
      box |= cv::Rect(tx, ty, 1, 1);
      due = due || std::max(std::abs(f[0]), std::abs(f[1])) >= 0.5;
    }
  }
  if (!due) return false;
  *move = MoveFromTiles(anchor->background_pending, box, anchor->surface.size());
  anchor->background_pending.setTo(0);
  return true;
}

void MovePaintedBuffer(const AnchorMove& move, const RefineAnchor& anchor, PaintedBuffer* painted) {
  const MoveMap m(move, move.roi, painted->bgra.size());
  cv::Mat alpha_before, alpha;
  cv::extractChannel(painted->bgra(m.roi), alpha_before, 3);
  const int surface_before = cv::countNonZero(alpha_before & anchor.surface(m.roi));
  cv::extractChannel(painted->bgra(m.source), alpha, 3);
  // Unpainted texels take their painted neighbours' colours first, so that a texel moved
  // next to them does not blend in what they hold; the paint's extent moves as it is.
  cv::Mat source_bgra = painted->bgra(m.source).clone();
  ExtendColours(&source_bgra, alpha);
  cv::remap(alpha, alpha, m.map, cv::noArray(), cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  cv::Mat bgra;
  cv::remap(source_bgra, bgra, m.map, cv::noArray(), cv::INTER_CUBIC, cv::BORDER_REPLICATE);
  cv::insertChannel(alpha, bgra, 3);
  bgra.copyTo(painted->bgra(m.roi));
  // Each texel keeps the sharpness of the sample it moved with: the same sample, now where it
  // belongs, so the quality rule keeps it against blurrier frames as before the move.
  m.Moved(painted->quality, cv::INTER_NEAREST, cv::BORDER_CONSTANT).copyTo(painted->quality(m.roi));
  painted->painted_surface_texels +=
      cv::countNonZero(alpha & anchor.surface(m.roi)) - surface_before;
}

void MoveWarpedImages(const AnchorMove& move, const cv::Rect& within, cv::Mat* bgr, cv::Mat* valid,
                      cv::Mat* quality) {
  const cv::Rect roi = move.roi & within;
  if (roi.empty()) return;
  const MoveMap m(move, roi, bgr->size());
  m.Moved(*bgr, cv::INTER_CUBIC, cv::BORDER_REPLICATE).copyTo((*bgr)(roi));
  m.Moved(*quality, cv::INTER_NEAREST, cv::BORDER_CONSTANT).copyTo((*quality)(roi));
  cv::Mat moved = m.Moved(*valid, cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  cv::erode(moved, moved, cv::Mat());
  moved.copyTo((*valid)(roi));
}

}  // namespace fresco
