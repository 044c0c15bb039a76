// The one policy for frames that cannot be painted as they are, the same for every source
// (files, live) and every client (`fresco run`, `fresco bench`, the app's worker):
//
//   no pose                -> not painted, counted (frames_without_pose); the run goes on
//   pose, camera unknown   -> bad input: "POSES: image 'NAME': camera N not found"
//   frame size != camera's -> bad input: "VIDEO: frame 'NAME' is WxH but the camera is WxH"
//   frame that fails to decode, truncated video -> bad input: the source's error, naming
//                             the file (PosedFrameSource::Next)
//
// Bad input ends the run with that one-line message; the CLI exits 2 with it, the app shows
// it as its status ("error: ..."). Running out of memory ends it too (exit 1 in the CLI; the
// app's worker drops the session): OutOfMemoryMessage() says what needs less.
#pragma once

#include <exception>
#include <string>

#include "pipeline/core/status.h"
#include "pipeline/run/posed_frame_source.h"

namespace fresco {

enum class FrameFate {
  kPaint,    // posed, its camera known, its size the camera's
  kNoPose,   // skipped and counted
  kHeldOut,  // posed, but held out of painting (`fresco bench` scores it; PaintRunOptions)
  kSkipped,  // a shard's frame whose view meets none of its buffers: not read, not painted

};

// kPaint or kNoPose, or an error naming `origin`'s file and the frame.
Status ApplyFramePolicy(const SourcedFrame& frame, const FrameOrigin& origin, FrameFate* fate);

// "out of memory (...); fewer texels (...) or fewer charts (...) need less": the same words
// from the CLI and the app.
std::string OutOfMemoryMessage();

// What a run that ended in an exception says, without the "fresco VERB: " or "error: "
// prefix: OutOfMemoryMessage() for std::bad_alloc and OpenCV's StsNoMem, "internal error:
// WHAT" for any other std::exception, "internal error" otherwise.
std::string FailureMessage(std::exception_ptr failure);

}  // namespace fresco
