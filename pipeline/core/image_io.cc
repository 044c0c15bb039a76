#include "pipeline/core/image_io.h"

#include <filesystem>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "pipeline/core/atomic_file.h"

namespace fresco {

Status WriteImageAtomic(const std::string& path, const cv::Mat& image) {
  if (image.empty()) return Status::Error(path + ": empty image");
  const std::string ext = std::filesystem::path(path).extension().string();
  std::vector<uchar> bytes;
  try {
    if (!cv::imencode(ext.empty() ? ".png" : ext, image, bytes))
      return Status::Error(path + ": could not encode image");
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": could not encode image (" + e.msg + ")");
  }
  return WriteFileAtomic(path, std::string(bytes.begin(), bytes.end()));
}

Status ReadImage(const std::string& path, cv::Mat* image, int flags) {
  if (!std::filesystem::exists(path)) return Status::Error(path + ": file not found");
  try {
    *image = cv::imread(path, flags);
  } catch (const cv::Exception& e) {
    return Status::Error(path + ": could not decode image (" + e.msg + ")");
  }
  if (image->empty()) return Status::Error(path + ": could not decode image");
  return Status::Ok();
}

}  // namespace fresco
