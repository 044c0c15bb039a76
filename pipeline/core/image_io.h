// Image files: atomic writes (temp file beside the target, then rename) with the format
// chosen by the target's extension, and reads whose errors name the file.
#pragma once

#include <string>

#include <opencv2/core.hpp>

#include "pipeline/core/status.h"

namespace fresco {

// Writes `image` to `path` (format by extension: .png, .jpg, ...), atomically.
Status WriteImageAtomic(const std::string& path, const cv::Mat& image);
// The same as a plain write (no temp file, no fsync): only for files inside a StagedFolder,
// whose Commit() is the atomic step.
Status WriteImage(const std::string& path, const cv::Mat& image);
// Reads an image (cv::IMREAD_UNCHANGED by default); a missing, truncated (PNG, JPEG) or
// undecodable file is an error naming it.
Status ReadImage(const std::string& path, cv::Mat* image, int flags = -1);

}  // namespace fresco
