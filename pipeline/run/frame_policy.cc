#include "pipeline/run/frame_policy.h"

#include "pipeline/core/capture.h"

namespace fresco {

Status ApplyFramePolicy(const SourcedFrame& frame, const FrameOrigin& origin, FrameFate* fate) {
  if (!frame.posed.has_pose) {
    *fate = FrameFate::kNoPose;
    return Status::Ok();
  }
  if (!frame.camera) {
    return Status::Error(origin.poses + ": image '" + frame.pose_name + "': camera " +
                         std::to_string(frame.camera_id) + " not found");
  }
  FRESCO_RETURN_IF_ERROR(CheckFrameSize(frame.posed.frame, *frame.camera, origin.video));
  *fate = FrameFate::kPaint;
  return Status::Ok();
}

}  // namespace fresco
