// Reads a video source one frame ahead on another thread (decoding a 1280x720 PNG takes
// about as long as painting it). Next() hands over the frame read in the background and
// starts reading the one after it.
#pragma once

#include <functional>
#include <future>
#include <utility>

#include "pipeline/core/status.h"
#include "pipeline/core/video_source.h"

namespace fresco {

class ReadAhead {
 public:
  // `skip` (optional): asked with the next frame's header (index, name, timestamp; no
  // pixels) where the source knows it before decoding (VideoSource::PeekNext); true: the
  // frame is passed over unread and handed out without pixels, as skipped.
  explicit ReadAhead(VideoSource* video, std::function<bool(const Frame&)> skip = nullptr)
      : video_(video), skip_(std::move(skip)) {
    Start();
  }
  ~ReadAhead() {
    if (pending_.valid()) pending_.wait();
  }
  ReadAhead(const ReadAhead&) = delete;
  ReadAhead& operator=(const ReadAhead&) = delete;

  // False at the end of the video, or on an error (then in `status`); stays so after it.
  // `skipped` (optional): set when the frame was passed over unread (the `skip` above).
  bool Next(Frame* frame, Status* status, bool* skipped = nullptr) {
    if (!pending_.valid()) return false;
    Result r = pending_.get();
    *status = r.status;
    if (!r.ok) return false;
    *frame = std::move(r.frame);
    if (skipped) *skipped = r.skipped;
    Start();
    return true;
  }

 private:
  struct Result {
    bool ok = false;
    bool skipped = false;
    Frame frame;
    Status status;
  };
  void Start() {
    pending_ = std::async(std::launch::async, [this] {
      Result r;
      if (skip_ && video_->PeekNext(&r.frame) && skip_(r.frame)) {
        video_->SkipNext();
        r.ok = r.skipped = true;
        return r;
      }
      r.ok = video_->Next(&r.frame, &r.status);
      return r;
    });
  }
  VideoSource* video_;
  std::function<bool(const Frame&)> skip_;
  std::future<Result> pending_;
};

}  // namespace fresco
