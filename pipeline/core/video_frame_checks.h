// What every video source checks of the frames it reads (video_source.cc's folders of images,
// video_capture_source.cc's video files and live sources).
#pragma once

#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/status.h"

namespace fresco {

// Frames of a folder, or of a video that says no rate: their timestamps' rate.
constexpr double kDefaultFolderFps = 30.0;

inline std::string SizeText(const cv::Size& size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

// Any 8-bit image to CV_8UC3 BGR; false for what cannot be converted.
inline bool ToBgr8(const cv::Mat& in, cv::Mat* out) {
  if (in.empty() || in.depth() != CV_8U) return false;
  switch (in.channels()) {
    case 3:
      *out = in;
      return true;
    case 1:
      cv::cvtColor(in, *out, cv::COLOR_GRAY2BGR);
      return true;
    case 4:
      cv::cvtColor(in, *out, cv::COLOR_BGRA2BGR);
      return true;
    default:
      return false;
  }
}

// Frames that must all have the first frame's size.
class SizeCheck {
 public:
  Status Check(const cv::Mat& image, const std::string& what) {
    if (first_size_.area() == 0) {
      first_size_ = image.size();
      first_what_ = what;
      return Status::Ok();
    }
    if (image.size() != first_size_) {
      return Status::Error(what + ": frame size " + SizeText(image.size()) +
                           " differs from the first frame's " + SizeText(first_size_) + " (" +
                           first_what_ + ")");
    }
    return Status::Ok();
  }

 private:
  cv::Size first_size_;
  std::string first_what_;
};

}  // namespace fresco
