// Movers followed by their colours: a mover the masks found in a frame (mover_masks.h) is
// looked for in the frames next to it, where the comparison across views missed it (a
// plain-coloured mover matches the frames near it that show it too). Pure image work on the
// masks and the frames at the reduced size the masks are made at.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace fresco {

// The colours of a set of pixels: 16 grey levels a bin per channel, the bins met at least
// min_count times together with their neighbouring bins (a mover's shading between them).
class ColourSet {
 public:
  ColourSet() = default;
  // The colours of `bgr` (CV_8UC3) where `pixels` (CV_8U, same size) is set.
  static ColourSet Of(const cv::Mat& bgr, const cv::Mat& pixels, int min_count);
  bool Contains(const cv::Vec3b& bgr) const { return !bins_.empty() && bins_[Bin(bgr)]; }

 private:
  static int Bin(const cv::Vec3b& c) { return (c[0] >> 4) * 256 + (c[1] >> 4) * 16 + (c[2] >> 4); }
  std::vector<uint8_t> bins_;
};

struct FollowFrame {
  cv::Mat bgr;       // CV_8UC3 at the masks' size (empty: not followed into)
  cv::Mat joinable;  // CV_8U: pixels that may join a mover by their colour
};

// Each frame's masked blobs (at least 8 pixels, of colours that less than a third of the pixels
// around them share) followed forwards, then backwards, up to `frames_away` frames: in the next
// frame, within the blob's box grown by a third of its size, the joinable pixels of its colours
// (in parts of at least 8 pixels) join that frame's mask when they are between half and twice
// the blob's pixels (else the blob is not followed further). What a blob gathers there is
// followed on with its original colours.
void FollowMovers(const std::vector<FollowFrame>& frames, int frames_away,
                  std::vector<cv::Mat>* masks);

}  // namespace fresco
