// Image encoding and decoding without linking OpenCV's image codecs, whose ~100 shared
// libraries (GDAL, GDCM, OpenEXR, ...) cost every process ~0.07 s of CPU in the dynamic loader
// at its start. PNG is encoded here and colour JPEG decoded here, with the settings OpenCV 4.6
// uses (the same bytes as cv::imencode, the same pixels as cv::imdecode); every other format
// and case goes through OpenCV's codecs in a module of Fresco's own (libfresco_codecs.so),
// loaded the first time one is needed.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace fresco {

// cv::imencode(ext, image, bytes): false where it fails (`error`: empty) or throws (`error`:
// its message).
bool EncodeImageBytes(const std::string& ext, const cv::Mat& image, std::vector<uchar>* bytes,
                      std::string* error = nullptr);

// cv::imdecode(bytes, flags): empty where it fails (`error`: empty) or throws (`error`: its
// message).
cv::Mat DecodeImageBytes(const void* data, size_t size, int flags, std::string* error = nullptr);

// The module's entry points, looked up by these names (image_codecs_module.cc).
using EncodeImageFunction = bool (*)(const std::string& ext, const cv::Mat& image,
                                     std::vector<uchar>* bytes, std::string* error);
using DecodeImageFunction = bool (*)(const void* data, size_t size, int flags, cv::Mat* image,
                                     std::string* error);
inline constexpr char kEncodeImageSymbol[] = "FrescoEncodeImage";
inline constexpr char kDecodeImageSymbol[] = "FrescoDecodeImage";

}  // namespace fresco
