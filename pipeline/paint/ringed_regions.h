// Regions of one colour ringed by a mask: a plain mover that the frames near it show over the
// same surface (large, slow, or moving with the camera) differs from them only at its edges, so
// the comparison across views (mover_masks.h) masks a ring around it and not its inside. The
// inside is a region of one colour whose boundary is mostly masked. Pure image work at the size
// the masks are made at.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace fresco {

struct RingedRegionOptions {
  // Neighbouring pixels (4-connected) whose colours are within this many grey levels on every
  // channel are one region (a mover's shading joins; its edge against the background does not).
  int levels = 8;
  // A region joins the mask when at least this share of its boundary is within two pixels of a
  // masked pixel ...
  double share = 0.5;
  // ... it has at least this many pixels, and at most this share of the frame's.
  int min_px = 12;
  double max_share = 0.25;
};

// Labels (CV_32S, 0 .. *count - 1) of the regions of one colour of `bgr` (CV_8UC3).
cv::Mat ColourRegions(const cv::Mat& bgr, int levels, int* count);

// A frame's ColourRegions and their boundaries, kept between calls of RingedRegions on the
// same image and surface (the passes of mover_masks.h judge a frame several times; its
// regions do not change, only the mask).
struct ColourRegionLabels {
  cv::Mat labels;  // empty until made
  int count = 0;
  cv::Mat on_boundary;              // CV_8U, 1 where a pixel meets another region's surface pixel
  std::vector<int> area, boundary;  // per region: pixels, of which on its boundary
};

// The regions of `bgr` ringed by `mask` (CV_8U, bgr's size): CV_8U, 255 on their pixels.
// `surface` (CV_8U, the same size): pixels that show the mesh. A region's boundary is where it
// meets another region's surface pixel; where it meets the image's border or pixels off the
// surface (the sky), nothing tells what it is, and that part does not count.
// `regions` (optional): bgr's colour regions at options.levels and their boundaries on
// `surface`, made here when empty.
cv::Mat RingedRegions(const cv::Mat& bgr, const cv::Mat& mask, const cv::Mat& surface,
                      const RingedRegionOptions& options, ColourRegionLabels* regions = nullptr);

}  // namespace fresco
