// PNG encoding chosen for fast decoding: every row filtered with "Up" (the row above
// subtracted) and zlib level 6. OpenCV's encoder picks libpng's adaptive filters, whose
// Paeth rows take most of the decoding time: a 1280x720 cube-room frame decodes in 14.0 ms
// instead of 24.4 ms (one thread) and is 7 % smaller (`build/tests/paint_bench
// --benchmark_filter=Decode`, BM_DecodeFrame). Lossless: decodes to exactly the same pixels.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/status.h"

namespace fresco {

// `image`: CV_8UC1 (grey) or CV_8UC3 (BGR, as OpenCV holds colour). Replaces `png`.
Status EncodeFastDecodingPng(const cv::Mat& image, std::vector<uint8_t>* png);

}  // namespace fresco
