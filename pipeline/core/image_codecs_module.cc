// The codecs module (libfresco_codecs.so, image_codecs.h): OpenCV's image codecs for what
// Fresco does not encode or decode itself.
#include <opencv2/imgcodecs.hpp>

#include "pipeline/core/image_codecs.h"

extern "C" __attribute__((visibility("default"))) bool FrescoEncodeImage(const std::string& ext,
                                                                         const cv::Mat& image,
                                                                         std::vector<uchar>* bytes,
                                                                         std::string* error) {
  try {
    if (cv::imencode(ext, image, *bytes)) return true;
    error->clear();
  } catch (const cv::Exception& e) {
    *error = e.msg;
  }
  return false;
}

extern "C" __attribute__((visibility("default"))) bool FrescoDecodeImage(const void* data,
                                                                         size_t size, int flags,
                                                                         cv::Mat* image,
                                                                         std::string* error) {
  try {
    const cv::Mat bytes(1, static_cast<int>(size), CV_8U, const_cast<void*>(data));
    *image = cv::imdecode(bytes, flags);
    if (!image->empty()) return true;
    error->clear();
  } catch (const cv::Exception& e) {
    *error = e.msg;
  }
  image->release();
  return false;
}
