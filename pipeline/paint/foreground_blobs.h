// The background model's raw foreground of one buffer, cleaned: 8-connected blobs of fewer
// than `min_blob_texels` texels dropped (noise), what is left dilated by an ellipse of radius
// `dilate_texels` (the texels around a mover, which its edge blurs). The same mask as
// cv::connectedComponentsWithStats, the area test and cv::dilate with
// cv::getStructuringElement(MORPH_ELLIPSE, 2r + 1) give, computed on the runs of foreground
// texels along the rows instead of on every texel: a mover or some noise covers a small part
// of a buffer, and the three OpenCV passes over the whole region cost 12 ms a frame on a
// 1416x1064 photo's 1.4 M texels (the union-find over runs: under 1 ms).
#pragma once

#include <opencv2/core.hpp>

namespace fresco {

// `raw`: CV_8U, nonzero = foreground. `out`: CV_8U of raw's size, all zero on entry; gets 255
// where the cleaned foreground is. Returns the number of blobs dropped.
int CleanForeground(const cv::Mat& raw, int min_blob_texels, int dilate_texels, cv::Mat* out);

}  // namespace fresco
