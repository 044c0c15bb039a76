// JPEG frames decoded straight into BGR by libjpeg-turbo. OpenCV 4.6 decodes a colour JPEG
// to RGB and swaps the channels pixel by pixel in a scalar loop; on a 1416x1064 photo that
// swap costs about as much as a third of the decoding. Same library, same inverse DCT and
// upsampling: the same pixels as cv::imdecode(IMREAD_COLOR).
#pragma once

#include <cstddef>
#include <string>

#include <opencv2/core.hpp>

namespace fresco {

// Decodes `bytes` (a whole JPEG file) into 8-bit BGR. Returns false, leaving `image` empty,
// where this path does not apply and cv::imdecode must decide: not a JPEG, not 1 or 3
// components (CMYK), an EXIF orientation other than upright, or a decoding error.
bool DecodeJpegBgr(const std::string& bytes, cv::Mat* image);
bool DecodeJpegBgr(const void* data, size_t size, cv::Mat* image);

}  // namespace fresco
