// Reads a video source one frame ahead on another thread (decoding a 1280x720 PNG takes
// about as long as painting it). Next() hands over the frame read in the background and
// starts reading the one after it.
#pragma once

#include <future>
#include <utility>

#include "pipeline/core/status.h"
#include "pipeline/core/video_source.h"

namespace fresco {

class ReadAhead {
 public:
  explicit ReadAhead(VideoSource* video) : video_(video) { Start(); }
  ~ReadAhead() {
    if (pending_.valid()) pending_.wait();
  }
  ReadAhead(const ReadAhead&) = delete;
  ReadAhead& operator=(const ReadAhead&) = delete;

  // False at the end of the video, or on an error (then in `status`); stays so after it.
  bool Next(Frame* frame, Status* status) {
    if (!pending_.valid()) return false;
    Result r = pending_.get();
    *status = r.status;
    if (!r.ok) return false;
    *frame = std::move(r.frame);
    Start();
    return true;
  }

 private:
  struct Result {
    bool ok = false;
    Frame frame;
    Status status;
  };
  void Start() {
    pending_ = std::async(std::launch::async, [this] {
      Result r;
      r.ok = video_->Next(&r.frame, &r.status);
      return r;
    });
  }
  VideoSource* video_;
  std::future<Result> pending_;
};

}  // namespace fresco
