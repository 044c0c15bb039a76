// Consensus anchoring for the refinement stage (refine_alignment.h).
//
// Registering each frame to what a base buffer already holds makes the frames agree with
// each other, but not with the model: the buffer was first painted by frames with their own
// pose errors, and every frame registered to it inherits that offset (the buffer's "gauge").
// Pose errors differ from frame to frame and average out, so the mean of the corrections a
// buffer has asked for estimates its gauge: with T_i = G * E_i^-1 (G the buffer's offset,
// E_i frame i's), mean(T_i) -> G as E_i^-1 averages to the identity.
//
// The gauge varies over a large buffer (each part was first painted by other frames), so it
// is kept as a field: per tile of kAnchorTileTexels, the sums and count of the displacements
// the frames' corrections ask for there. When the mean at some tile with enough samples
// exceeds the step, the buffer's content is moved back by the (smoothed) mean field once
// (bicubic; only tiles the frame sees) and the sums are re-expressed in the
// moved buffer, so the estimate keeps every sample and sharpens as 1/sqrt(frames).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/project.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/paint_update.h"

namespace fresco {

inline constexpr int kAnchorTileTexels = 32;

struct RefineAnchor {
  cv::Mat sum;    // CV_64FC2, per tile: sum of displacements (x, y) asked for, texels
  cv::Mat count;  // CV_64F, per tile: how many frames asked
  // Per tile: moves not yet applied to the buffer's background model, which moves by whole
  // texels (TakeBackgroundMove).
  cv::Mat background_pending;  // CV_64FC2
  cv::Mat surface;             // CV_8U, buffer size: 255 on the surface (not gutter)
  int samples = 0;             // frames registered to this buffer
  int moves = 0;               // times the buffer was moved
  double largest_move_px = 0;  // the largest displacement of any move, texels
};

// A move of a buffer's content: what is at q + field(q - roi.tl()) belongs at q, for q in
// roi; nothing moves outside it.
struct AnchorMove {
  cv::Rect roi;
  cv::Mat field;  // CV_32FC2, roi size, texels
};

void InitRefineAnchor(const BaseBuffer& buffer, RefineAnchor* anchor);

// The anchor's tiles (CV_8U, 1 or 0) holding any of `points` (texels).
cv::Mat TilesAt(const RefineAnchor& anchor, const std::vector<cv::Point2f>& points);

// The anchor's tiles holding any texel set in `valid` (CV_8U, buffer size) within `box`.
cv::Mat TilesSet(const RefineAnchor& anchor, const cv::Mat& valid, const cv::Rect& box);

// Adds a frame's correction `buffer_from_warped` (identity when none was needed) as a sample
// at the tiles `measured` (TilesAt, TilesSet): where the correction holds. A homography fitted
// to one buffer's matches holds where its inliers are (not extrapolated); a correction
// derived from the frame's pose (refine_pose.h) holds wherever the frame sees the buffer.
// Returns true, with the move, when the buffer should move; the anchor is then re-expressed
// in the moved buffer. Only tiles in `in_view` move: the frame repaints those right after,
// while content out of view would be resampled on old evidence.
bool AddAnchorSample(const cv::Matx33d& buffer_from_warped, const cv::Mat& measured,
                     const cv::Mat& in_view, const RefineOptions& options, RefineAnchor* anchor,
                     AnchorMove* move);

// When the moves not yet applied to the background model reach half a texel somewhere:
// their sum, to move the model by (BufferBackground::Move rounds it per texel); they are
// then cleared.
bool TakeBackgroundMove(RefineAnchor* anchor, AnchorMove* move);

// Largest displacement of `region`'s corners under `H`, texels.
double LargestDisplacement(const cv::Matx33d& H, const cv::Rect& region);

// Moves the painted content: colour bicubic, alpha and quality nearest (a texel keeps its
// sample's sharpness, so later frames replace it by the quality rule as before).
void MovePaintedBuffer(const AnchorMove& move, const RefineAnchor& anchor, PaintedBuffer* painted);

// The same move for a frame's warped images (bgr bicubic, valid and quality nearest), where
// they may be valid (`within`, WarpedBuffer::valid_box).
void MoveWarpedImages(const AnchorMove& move, const cv::Rect& within, cv::Mat* bgr, cv::Mat* valid,
                      cv::Mat* quality);

}  // namespace fresco
