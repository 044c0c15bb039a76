// Image comparison metrics used by tests, `fresco run` truth figures and `fresco bench`'s
// virtual rephotography: PSNR and 1 - NCC over a mask.
#pragma once

#include <opencv2/core.hpp>

namespace fresco {

// PSNR (dB, 8-bit peak 255) between two images of the same size and type (1-4 channels,
// 8-bit), over the pixels where `mask` (CV_8U) is non-zero (all pixels when empty).
// Returns +inf for identical images and NaN when the mask is empty.
double PsnrDb(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask = cv::Mat());
// 1 - normalized cross-correlation of the grey values over the mask (0 = identical up to
// gain and offset; 1 = uncorrelated). NaN when the mask is empty or an image is flat.
double OneMinusNcc(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask = cv::Mat());
// Local 1 - NCC (virtual rephotography, Waechter et al. 2017): the grey values' normalized
// cross-correlation in every `window` x `window` box, 1 - it averaged over the pixels whose
// whole box lies in `mask` (the mask eroded by the box). Insensitive to exposure (gain and
// offset per box), sensitive to blur, seams and misalignment. A box flat in either image
// counts as uncorrelated (1). NaN when no pixel's box lies in the mask.
double LocalOneMinusNcc(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask, int window = 9);

}  // namespace fresco
