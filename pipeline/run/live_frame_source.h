// Posed frames from a project's live inputs (pipeline/live/live_input.h: a live video, a
// pose feed or a TUM file matched by time), behind the same interface as files: what
// `fresco run` paints from a live project. A pose feed that fails ends the source with its
// error.
#pragma once

#include "pipeline/live/live_input.h"
#include "pipeline/run/posed_frame_source.h"

namespace fresco {

class LiveFrameSource : public PosedFrameSource {
 public:
  // `inputs` (opened by OpenLiveInputs) must outlive the source; `origin`: the resolved
  // video and poses addresses.
  LiveFrameSource(LiveInputs* inputs, FrameOrigin origin)
      : inputs_(inputs), origin_(std::move(origin)) {}

  FrameRead Next(SourcedFrame* frame, Status* status) override;
  int NumStreams() const override { return 1; }
  const FrameOrigin& Origin(int stream) const override { return origin_; }
  std::string EndReason() const override;
  void Stop() override { inputs_->frames->Stop(); }
  bool RealTime() const override { return inputs_->frames->RealTime(); }

 private:
  LiveInputs* inputs_;
  FrameOrigin origin_;
};

}  // namespace fresco
