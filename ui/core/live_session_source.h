// The app's live frames (LiveSession: the live core of `fresco run`, read on a feeder
// thread) as a source of posed frames for a PaintRun (pipeline/run/posed_frame_source.h):
// each Next waits at most `poll_ms` for a frame (kWaiting otherwise), so the worker stays
// responsive while a source stalls.
#pragma once

#include <string>

#include "pipeline/run/posed_frame_source.h"
#include "ui/core/live_session.h"

namespace fresco {

class LiveSessionSource : public PosedFrameSource {
 public:
  // `live` must outlive the source.
  LiveSessionSource(LiveSession* live, int poll_ms, FrameOrigin origin)
      : live_(live), poll_ms_(poll_ms), origin_(std::move(origin)) {}

  FrameRead Next(SourcedFrame* frame, Status* status) override;
  int NumStreams() const override { return 1; }
  const FrameOrigin& Origin(int stream) const override { return origin_; }
  std::string EndReason() const override { return end_reason_; }

 private:
  LiveSession* live_;
  int poll_ms_;
  FrameOrigin origin_;
  std::string end_reason_ = "live video ended";
};

}  // namespace fresco
