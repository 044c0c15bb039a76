// Video frames from a folder of images (sorted by file name) or a video file OpenCV reads.
// Frames are streamed: memory does not grow with the video's length.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/status.h"

namespace fresco {

struct Frame {
  int index = -1;        // 0-based position in the stream
  std::string name;      // file name for folders ("000012.png"); "%06d" index for videos
  double timestamp_s = 0.0;
  cv::Mat bgr;           // CV_8UC3
};

class VideoSource {
 public:
  virtual ~VideoSource() = default;
  // Reads the next frame. Returns false at the end of the stream; a frame that fails to
  // decode sets `status` to an error naming it and returns false.
  virtual bool Next(Frame* frame, Status* status) = 0;
  // Number of frames when known in advance, else -1.
  virtual int FrameCount() const = 0;
  // Frame names in order when known (folders), else empty.
  virtual std::vector<std::string> FrameNames() const = 0;
  virtual double Fps() const = 0;
};

// `path`: a folder of images (.png .jpg .jpeg .bmp .tif .tiff .ppm) or a video file.
Status OpenVideoSource(const std::string& path, std::unique_ptr<VideoSource>* source);

}  // namespace fresco
