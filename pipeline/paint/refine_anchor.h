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
// is kept as a field: per tile of kAnchorTileTexels, the sum and count of the displacements
// the frames' corrections ask for there. When the mean at some tile with enough samples
// exceeds the step, the buffer's content is moved back by the (smoothed) mean field once
// (bicubic) and the sums are re-expressed in the moved buffer, so the estimate keeps every
// sample and sharpens as 1/sqrt(frames).
#pragma once

#include <opencv2/core.hpp>

#include "pipeline/core/project.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/paint_update.h"

namespace fresco {

inline constexpr int kAnchorTileTexels = 32;

struct RefineAnchor {
  cv::Mat sum;    // CV_64FC2, per tile: sum of displacements (x, y) asked for, texels
  cv::Mat count;  // CV_64F, per tile: how many frames asked
  int samples = 0;         // frames registered to this buffer
  int moves = 0;           // times the buffer was moved
  double largest_move_px = 0;  // the largest displacement of any move, texels
  // Per tile: moves not yet applied to the buffer's background model, which moves by whole
  // texels (TakeBackgroundMove).
  cv::Mat background_pending;  // CV_64FC2
};

void InitRefineAnchor(const BaseBuffer& buffer, RefineAnchor* anchor);

// Adds a frame's correction `buffer_from_warped` (identity when none was needed) over
// `region`. Returns true, with the displacement `field` (CV_32FC2, buffer size: content at
// q + field(q) belongs at q) when the buffer should move; the anchor is then re-expressed in
// the moved buffer.
bool AddAnchorSample(const cv::Matx33d& buffer_from_warped, const cv::Rect& region,
                     const RefineOptions& options, RefineAnchor* anchor, cv::Mat* field);

// When the pending moves reach half a texel somewhere: the field to move the background
// model by (BufferBackground::Move rounds it per texel); the pending moves are then cleared.
bool TakeBackgroundMove(RefineAnchor* anchor, cv::Mat* field);

// Largest displacement of `region`'s corners under `H`, texels.
double LargestDisplacement(const cv::Matx33d& H, const cv::Rect& region);

// Moves the painted content by `field` (see AddAnchorSample): colour bicubic, alpha and
// quality nearest. Moved texels get quality 0, so that later frames (registered to the
// moved buffer) replace them.
void MovePaintedBuffer(const cv::Mat& field, const BaseBuffer& buffer, PaintedBuffer* painted);

// The same move for a frame's warped images (bgr bicubic, valid and quality nearest).
void MoveWarpedImages(const cv::Mat& field, cv::Mat* bgr, cv::Mat* valid, cv::Mat* quality);

}  // namespace fresco
