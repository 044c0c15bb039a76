// Video frames from a folder of images (sorted by file name), a video file OpenCV reads, or
// a live source: a camera ("device:N", V4L2 through OpenCV) or a stream URL OpenCV's FFmpeg
// backend reads ("udp://127.0.0.1:5000", "rtsp://...", "http://..."). Frames are streamed:
// memory does not grow with the video's length.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace fresco {

struct Frame {
  int index = -1;    // 0-based position in the stream
  std::string name;  // file name for folders ("000012.png"); "%06d" index for videos
  // Capture time, seconds, the first frame at 0. Folders: index / 30; files: the stream's
  // presentation time; live sources: the stream's presentation time when it has one
  // (VideoSourceOptions::stream_clock), else the arrival time below.
  double timestamp_s = 0.0;
  // Live sources: when the frame was received, seconds on the steady clock after the first
  // frame arrived (0 for files).
  double arrival_s = 0.0;
  cv::Mat bgr;  // CV_8UC3
  // Optional: pixels found to show moving objects (mover_masks.h: compared with the frames
  // near it through the mesh): CV_8U, 255 there, any size (scaled to the frame's). The
  // background model takes those that touch the foreground it flags for foreground too.
  // 128: pixels the frames near it agree with (the background model's growth does not start
  // from them).
  cv::Mat movers;
  // Optional: the mesh's depth seen from the frame's camera at `depth_cam_from_local` (CV_32F
  // camera z, +inf off the surface: Rasterizer::RasterizeDepth), kept by the whole-capture
  // pre-pass; painting's depth stage takes it instead of rasterizing when it paints the frame
  // at that pose exactly.
  cv::Mat depth;
  Rigid3d depth_cam_from_local;
};

class VideoSource {
 public:
  virtual ~VideoSource() = default;
  // Reads the next frame. Returns false at the end of the stream; a frame that fails to
  // decode sets `status` to an error naming it and returns false.
  virtual bool Next(Frame* frame, Status* status) = 0;
  // Number of frames when known in advance, else -1.
  virtual int FrameCount() const = 0;
  // Frame names in order when known (folders), else empty.
  virtual std::vector<std::string> FrameNames() const = 0;
  virtual double Fps() const = 0;
  // The next frame's index, name and timestamp without reading its pixels, where they are
  // known before (folders: nothing is read; video files: the next frame is grabbed, not yet
  // converted to BGR); false otherwise (live sources, the end: nothing to skip).
  virtual bool PeekNext(Frame* /*header*/) { return false; }
  // Passes over the next frame without reading it (after PeekNext said true; a video file's
  // grabbed frame is dropped unconverted).
  virtual void SkipNext() {}
  // Makes frame `index` (0-based) the next one read: a folder at once, a video file by
  // reading it again from the start up to there (exact whatever the codec's key frames).
  // False where the source cannot go back (live sources) or the video has no such frame.
  virtual bool Seek(int /*index*/) { return false; }
  // A camera or a stream (frames arrive on their own clock; reading may time out).
  virtual bool IsLive() const { return false; }
  // Which clock timestamp_s follows: "index" (folders), "stream" or "arrival".
  virtual std::string Clock() const { return "index"; }
  // Live sources: the last Next() returned false because no frame came within the read
  // timeout (a stall, or a stream that ends without saying so, like UDP), not because the
  // source reported its end (an HTTP or RTSP server that finished, a file's end).
  virtual bool TimedOut() const { return false; }
  // False for a protocol that carries no end of stream (UDP): a sender that finished and one
  // that stalled both time out.
  virtual bool SignalsEnd() const { return true; }
};

struct VideoSourceOptions {
  // Live sources: opening (the stream's first packets, probed by FFmpeg) must succeed within
  // this, and after that a frame must arrive within read_timeout_s, else reading ends.
  double open_timeout_s = 10.0;
  double read_timeout_s = 3.0;
  // Live sources: timestamps from the stream's presentation times (immune to network and
  // decoding jitter) when the stream has them; false: arrival times.
  bool stream_clock = true;
};

// `path`: a folder of images (.png .jpg .jpeg .bmp .tif .tiff .ppm) or a video file.
// `path` may also be "device:N" or a stream URL (live sources).
Status OpenVideoSource(const std::string& path, const VideoSourceOptions& options,
                       std::unique_ptr<VideoSource>* source);
Status OpenVideoSource(const std::string& path, std::unique_ptr<VideoSource>* source);

}  // namespace fresco
