// Video files and live sources (cameras, stream URLs) read through OpenCV's videoio, built as a
// module of its own (libfresco_video.so) that OpenVideoSource loads the first time it opens
// one: a run that reads folders of images never loads videoio and the ~100 shared libraries
// it brings (FFmpeg, GStreamer, ...), whose symbol lookups cost every process ~0.07 s of CPU
// in the dynamic loader at its start.
#pragma once

#include <memory>
#include <string>

#include "pipeline/core/status.h"
#include "pipeline/core/video_source.h"

namespace fresco {

enum class CaptureKind : int {
  kDevice = 0,  // "device:N", N checked already
  kStream = 1,  // a stream URL
  kFile = 2,    // a video file that exists
};

// The module's entry point, looked up by this name: opens `path` as `kind` into `source`, or
// sets `status` to a one-line error naming it.
using OpenCaptureSourceFunction = void (*)(int kind, const std::string& path,
                                           const VideoSourceOptions& options,
                                           std::unique_ptr<VideoSource>* source, Status* status);
inline constexpr char kOpenCaptureSourceSymbol[] = "FrescoOpenCaptureSource";

}  // namespace fresco
