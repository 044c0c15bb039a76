// The video module (libfresco_video.so, video_capture_source.h): video files and live sources
// through cv::VideoCapture, loaded by OpenVideoSource the first time it opens one.
#include "pipeline/core/video_capture_source.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/videoio.hpp>

#include "pipeline/core/video_frame_checks.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

// A video file or a live source through cv::VideoCapture.
class CaptureSource : public VideoSource {
 public:
  CaptureSource(std::string what, cv::VideoCapture capture, bool live,
                const VideoSourceOptions& options)
      : what_(std::move(what)),
        capture_(std::move(capture)),
        live_(live),
        stream_clock_(options.stream_clock),
        read_timeout_s_(options.read_timeout_s) {
    const double fps = capture_.get(cv::CAP_PROP_FPS);
    fps_ = std::isfinite(fps) && fps > 0 && fps < 1000 ? fps : kDefaultFolderFps;
    const double count = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    count_ = !live_ && std::isfinite(count) && count > 0 ? static_cast<int>(count) : -1;
  }

  // Video files: the next frame grabbed (demuxed and decoded by FFmpeg, not converted), so
  // that a frame skipped costs no conversion to BGR; a frame grabbed is Next()'s to retrieve.
  bool PeekNext(Frame* header) override {
    if (live_) return false;
    if (!grabbed_) grabbed_ = capture_.grab();
    if (!grabbed_) return false;  // the end: Next() says so (and whether it came too early)
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", index_);
    header->index = index_;
    header->name = name;
    header->timestamp_s = index_ / fps_;
    header->bgr.release();
    return true;
  }
  void SkipNext() override {
    if (!grabbed_) return;
    grabbed_ = false;
    ++index_;
  }

  bool Next(Frame* frame, Status* status) override {
    cv::Mat image;
    const auto read_start = std::chrono::steady_clock::now();
    timed_out_ = false;
    const bool was_grabbed = grabbed_;
    grabbed_ = false;
    const bool read =
        (was_grabbed ? capture_.retrieve(image) : capture_.read(image)) && !image.empty();
    const double read_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
    const double previous_read_s = last_read_s_;
    last_read_s_ = read_s;
    if (!read) {  // end of the stream
      // OpenCV tells neither why a read failed nor whether its read timeout fired. Only the
      // timeout makes a read last that long; when it fires, FFmpeg may still return a frame it
      // held (that read lasted the timeout) and then fails every read at once. FFmpeg reports
      // the end of a stream at once.
      timed_out_ =
          live_ && std::max(read_s, previous_read_s) >= kTimedOutFraction * read_timeout_s_;
      // A file that ends well before the frame count its header declares is truncated or
      // corrupt (one frame of slack: some containers only estimate the count).
      if (!live_ && count_ > 0 && index_ + 1 < count_ && status) {
        *status = Status::Error(what_ + ": ends after " + std::to_string(index_) + " of the " +
                                std::to_string(count_) +
                                " frames its header declares (truncated or corrupt file)");
      }
      return false;
    }
    const auto now = std::chrono::steady_clock::now();
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", index_);
    cv::Mat bgr;
    if (!ToBgr8(image, &bgr)) {
      if (status) *status = Status::Error(what_ + ": frame " + name + ": cannot convert to BGR");
      return false;
    }
    const Status size_ok = sizes_.Check(bgr, what_ + ": frame " + name);
    if (!size_ok.ok()) {
      if (status) *status = size_ok;
      return false;
    }
    if (index_ == 0) start_ = now;
    frame->index = index_;
    frame->name = name;
    frame->arrival_s = live_ ? std::chrono::duration<double>(now - start_).count() : 0.0;
    frame->timestamp_s = live_ ? LiveTimestamp(frame->arrival_s) : index_ / fps_;
    frame->bgr = bgr;
    ++index_;
    return true;
  }
  int FrameCount() const override { return count_; }
  bool Seek(int index) override {
    if (live_ || index < 0) return false;
    if (index < index_) {  // opened again: the decoder starts as it did the first time
      if (!capture_.open(what_, cv::CAP_FFMPEG)) return false;
      index_ = 0;
    }
    for (; index_ < index; ++index_)
      if (!capture_.grab()) return false;
    return true;
  }
  std::vector<std::string> FrameNames() const override { return {}; }
  double Fps() const override { return fps_; }
  bool IsLive() const override { return live_; }
  bool TimedOut() const override { return timed_out_; }
  bool SignalsEnd() const override { return what_.rfind("udp://", 0) != 0; }
  std::string Clock() const override {
    return !live_ ? "index" : (use_stream_clock_ ? "stream" : "arrival");
  }

 private:
  // The stream's presentation time relative to the first frame's, while it is finite and
  // increasing; otherwise (cameras without timestamps, a stream that restarts) arrival time
  // from then on. A stream whose first frame precedes its start time (RTSP: the first RTP
  // timestamp) has that frame's time clamped to the start by OpenCV, the same as the
  // second's: the second frame then counts as one frame period after the first.
  double LiveTimestamp(double arrival_s) {
    const double pts_ms = capture_.get(cv::CAP_PROP_POS_MSEC);
    if (index_ == 0) {
      first_pts_ms_ = pts_ms;
      use_stream_clock_ = stream_clock_ && std::isfinite(pts_ms) && pts_ms >= 0;
    }
    if (use_stream_clock_ && index_ == 1 && pts_ms == first_pts_ms_ && !IsCamera())
      first_pts_ms_ -= 1000.0 / fps_;
    if (use_stream_clock_) {
      const double t = (pts_ms - first_pts_ms_) / 1000.0;
      if (std::isfinite(t) && (index_ == 0 || t > last_t_)) {
        last_t_ = t;
        return t;
      }
      use_stream_clock_ = false;
      arrival_shift_ = last_t_ - arrival_s + 1.0 / fps_;  // continues after the last stamp
    }
    return arrival_s + arrival_shift_;
  }

  bool IsCamera() const { return what_.rfind("device:", 0) == 0; }

  std::string what_;
  cv::VideoCapture capture_;
  bool live_;
  // A failed read that lasted this fraction of the read timeout timed out.
  static constexpr double kTimedOutFraction = 0.9;

  bool stream_clock_;
  double read_timeout_s_;
  bool timed_out_ = false;
  bool grabbed_ = false;      // PeekNext grabbed the next frame
  double last_read_s_ = 0.0;  // how long the last read took
  bool use_stream_clock_ = false;
  double first_pts_ms_ = 0.0;
  double last_t_ = 0.0;
  double arrival_shift_ = 0.0;
  double fps_ = kDefaultFolderFps;
  int count_ = -1;
  int index_ = 0;
  std::chrono::steady_clock::time_point start_;
  SizeCheck sizes_;
};

// FFmpeg logs its complaints about a broken file on stderr, besides the one-line error
// Fresco gives: keep it quiet unless the user asked for its log (OPENCV_FFMPEG_LOGLEVEL,
// read by OpenCV when it first uses FFmpeg; -8 is AV_LOG_QUIET).
void QuietFfmpegLog() {
  static std::once_flag once;
  std::call_once(once, [] { setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", /*overwrite=*/0); });
}

Status OpenCapture(CaptureKind kind, const std::string& path, const VideoSourceOptions& options,
                   std::unique_ptr<VideoSource>* source) {
  const int open_ms = static_cast<int>(options.open_timeout_s * 1000);
  const int read_ms = static_cast<int>(options.read_timeout_s * 1000);
  std::error_code ec;
  if (kind == CaptureKind::kDevice) {
    const std::string number = path.substr(7);
    // Only the one-line error below: no device, or OpenCV's own warnings silenced.
    const std::string device = "/dev/video" + number;
    cv::VideoCapture capture;
    if (fs::exists(device, ec)) {
      const cv::utils::logging::LogLevel level =
          cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
      capture.open(std::stoi(number), cv::CAP_V4L2);
      cv::utils::logging::setLogLevel(level);
    }
    if (!capture.isOpened()) {
      return Status::Error(path + ": cannot open the camera (no /dev/video" + number +
                           ", or it is busy or not a capture device)");
    }
    *source = std::make_unique<CaptureSource>(path, std::move(capture), /*live=*/true, options);
    return Status::Ok();
  }
  QuietFfmpegLog();
  if (kind == CaptureKind::kStream) {
    cv::VideoCapture capture(
        path, cv::CAP_FFMPEG,
        {cv::CAP_PROP_OPEN_TIMEOUT_MSEC, open_ms, cv::CAP_PROP_READ_TIMEOUT_MSEC, read_ms});
    if (!capture.isOpened()) {
      return Status::Error(path + ": cannot open the stream within " +
                           std::to_string(open_ms / 1000.0).substr(0, 4) +
                           " s (unreachable, nothing sent, or not a format OpenCV's FFmpeg "
                           "backend reads)");
    }
    *source = std::make_unique<CaptureSource>(path, std::move(capture), /*live=*/true, options);
    return Status::Ok();
  }
  cv::VideoCapture capture(path, cv::CAP_FFMPEG);
  if (!capture.isOpened()) {
    return Status::Error(path + ": cannot open as a video (OpenCV FFmpeg backend)");
  }
  *source = std::make_unique<CaptureSource>(path, std::move(capture), /*live=*/false, options);
  return Status::Ok();
}

}  // namespace
}  // namespace fresco

// The entry point OpenVideoSource looks up (kOpenCaptureSourceSymbol).
extern "C" __attribute__((visibility("default"))) void FrescoOpenCaptureSource(
    int kind, const std::string& path, const fresco::VideoSourceOptions& options,
    std::unique_ptr<fresco::VideoSource>* source, fresco::Status* status) {
  try {
    *status = fresco::OpenCapture(static_cast<fresco::CaptureKind>(kind), path, options, source);
  } catch (const std::exception& e) {
    *status = fresco::Status::Error(path + ": cannot open as a video (" + e.what() + ")");
  }
}
