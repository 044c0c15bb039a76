#include "pipeline/run/frame_policy.h"

#include <new>

#include <opencv2/core.hpp>

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

std::string OutOfMemoryMessage() {
  return "out of memory (files already there are left as they were); fewer texels (a larger "
         "pipeline.texel_size_m or a smaller pipeline.max_buffer_texels) or fewer charts (a "
         "larger grouping.min_chart_texels) need less";
}

std::string FailureMessage(std::exception_ptr failure) {
  try {
    std::rethrow_exception(failure);
  } catch (const std::bad_alloc&) {
    return OutOfMemoryMessage();
  } catch (const cv::Exception& e) {
    if (e.code == cv::Error::StsNoMem) return OutOfMemoryMessage();
    return std::string("internal error: ") + e.what();
  } catch (const std::exception& e) {
    return std::string("internal error: ") + e.what();
  } catch (...) {
    return "internal error";
  }
}

}  // namespace fresco
