// PNG encoding chosen for fast decoding: every row filtered with "Up" (the row above
// subtracted) and zlib level 6. OpenCV's encoder picks libpng's adaptive filters, whose
// Paeth rows take most of the decoding time: on 1280x720 synthetic frames decoding drops from
// 17.4 to 10.9 ms per frame and the files shrink by 14 % (measured with imdecode, one thread,
// see README "Texture alignment refinement"). Lossless: decodes to exactly the same pixels.
#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/status.h"

namespace fresco {

// `image`: CV_8UC1 (grey) or CV_8UC3 (BGR, as OpenCV holds colour). Replaces `png`.
Status EncodeFastDecodingPng(const cv::Mat& image, std::vector<uint8_t>* png);

}  // namespace fresco
