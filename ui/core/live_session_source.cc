#include "ui/core/live_session_source.h"

namespace fresco {

FrameRead LiveSessionSource::Next(SourcedFrame* frame, Status* status) {
  std::string end;
  switch (live_->Next(poll_ms_, &frame->posed, &end)) {
    case LiveSession::Poll::kWaiting:
      return FrameRead::kWaiting;
    case LiveSession::Poll::kEnded: {
      const std::string error = "error: ";
      if (end.rfind(error, 0) == 0)
        *status = Status::Error(end.substr(error.size()));
      else
        end_reason_ = end;
      return FrameRead::kEnded;
    }
    case LiveSession::Poll::kFrame:
      break;
  }
  frame->camera = frame->posed.has_pose ? &live_->camera() : nullptr;
  frame->camera_id = -1;
  frame->pose_name = frame->posed.frame.name;
  frame->pose_index = -1;
  frame->stream = 0;
  return FrameRead::kFrame;
}

}  // namespace fresco
