#include "pipeline/run/live_frame_source.h"

namespace fresco {

FrameRead LiveFrameSource::Next(SourcedFrame* frame, Status* status) {
  const auto feed_failed = [&] {
    if (!inputs_->feed) return false;
    *status = inputs_->feed->error();
    return !status->ok();
  };
  if (feed_failed()) return FrameRead::kEnded;
  if (!inputs_->frames->Next(&frame->posed, status)) {
    if (status->ok()) feed_failed();
    return FrameRead::kEnded;
  }
  if (feed_failed()) return FrameRead::kEnded;
  frame->camera = frame->posed.has_pose ? inputs_->camera : nullptr;
  frame->camera_id = -1;
  frame->pose_name = frame->posed.frame.name;
  frame->pose_index = -1;
  frame->stream = 0;
  return FrameRead::kFrame;
}

std::string LiveFrameSource::EndReason() const {
  return "live video ended: " + inputs_->frames->stats().end_reason;
}

}  // namespace fresco
