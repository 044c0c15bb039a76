// Video sources, streamed one frame at a time: a folder of images (sorted by file name), a
// video file (OpenCV's FFmpeg backend), or a live source ("device:N", a stream URL).
#include "pipeline/core/video_source.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "pipeline/core/image_io.h"
#include "pipeline/core/project.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

constexpr double kDefaultFolderFps = 30.0;

bool IsImageFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  static const char* kExtensions[] = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".ppm"};
  for (const char* e : kExtensions) {
    if (ext == e) return true;
  }
  return false;
}

std::string SizeText(const cv::Size& size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

// Any 8-bit image to CV_8UC3 BGR; false for what cannot be converted.
bool ToBgr8(const cv::Mat& in, cv::Mat* out) {
  if (in.empty() || in.depth() != CV_8U) return false;
  switch (in.channels()) {
    case 3:
      *out = in;
      return true;
    case 1:
      cv::cvtColor(in, *out, cv::COLOR_GRAY2BGR);
      return true;
    case 4:
      cv::cvtColor(in, *out, cv::COLOR_BGRA2BGR);
      return true;
    default:
      return false;
  }
}

// Frames that must all have the first frame's size.
class SizeCheck {
 public:
  Status Check(const cv::Mat& image, const std::string& what) {
    if (first_size_.area() == 0) {
      first_size_ = image.size();
      first_what_ = what;
      return Status::Ok();
    }
    if (image.size() != first_size_) {
      return Status::Error(what + ": frame size " + SizeText(image.size()) +
                           " differs from the first frame's " + SizeText(first_size_) + " (" +
                           first_what_ + ")");
    }
    return Status::Ok();
  }

 private:
  cv::Size first_size_;
  std::string first_what_;
};

class FolderSource : public VideoSource {
 public:
  FolderSource(std::string folder, std::vector<std::string> names)
      : folder_(std::move(folder)), names_(std::move(names)) {}

  bool Next(Frame* frame, Status* status) override {
    if (next_ >= names_.size()) return false;
    const std::string& name = names_[next_];
    const std::string path = (fs::path(folder_) / name).string();
    cv::Mat image, bgr;
    if (Status read = ReadImage(path, &image, cv::IMREAD_COLOR); !read.ok()) {
      if (status) *status = read;
      return false;
    }
    if (!ToBgr8(image, &bgr)) {
      if (status) *status = Status::Error(path + ": cannot decode the image");
      return false;
    }
    const Status size_ok = sizes_.Check(bgr, path);
    if (!size_ok.ok()) {
      if (status) *status = size_ok;
      return false;
    }
    frame->index = static_cast<int>(next_);
    frame->name = name;
    frame->timestamp_s = next_ / kDefaultFolderFps;
    frame->bgr = bgr;
    ++next_;
    return true;
  }
  int FrameCount() const override { return static_cast<int>(names_.size()); }
  std::vector<std::string> FrameNames() const override { return names_; }
  double Fps() const override { return kDefaultFolderFps; }
  bool PeekNext(Frame* header) override {
    if (next_ >= names_.size()) return false;
    header->index = static_cast<int>(next_);
    header->name = names_[next_];
    header->timestamp_s = next_ / kDefaultFolderFps;
    header->bgr.release();
    return true;
  }
  void SkipNext() override {
    if (next_ < names_.size()) ++next_;
  }
  bool Seek(int index) override {
    if (index < 0 || static_cast<size_t>(index) > names_.size()) return false;
    next_ = static_cast<size_t>(index);
    return true;
  }

 private:
  std::string folder_;
  std::vector<std::string> names_;
  size_t next_ = 0;
  SizeCheck sizes_;
};

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

Status OpenFolder(const std::string& path, std::unique_ptr<VideoSource>* source) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path& entry = it->path();
    const std::string name = entry.filename().string();
    if (name.empty() || name[0] == '.') continue;  // hidden files, atomic-write temp files
    if (!IsImageFile(entry) || !it->is_regular_file(ec)) continue;
    names.push_back(name);
  }
  if (ec) return Status::Error(path + ": cannot list the folder: " + ec.message());
  if (names.empty()) {
    return Status::Error(path +
                         ": no image frames in the folder (.png .jpg .jpeg .bmp .tif .tiff .ppm)");
  }
  std::sort(names.begin(), names.end());
  *source = std::make_unique<FolderSource>(path, std::move(names));
  return Status::Ok();
}

// FFmpeg logs its complaints about a broken file on stderr, besides the one-line error
// Fresco gives: keep it quiet unless the user asked for its log (OPENCV_FFMPEG_LOGLEVEL,
// read by OpenCV when it first uses FFmpeg; -8 is AV_LOG_QUIET).
void QuietFfmpegLog() {
  static std::once_flag once;
  std::call_once(once, [] { setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", /*overwrite=*/0); });
}

}  // namespace

Status OpenVideoSource(const std::string& path, const VideoSourceOptions& options,
                       std::unique_ptr<VideoSource>* source) {
  const int open_ms = static_cast<int>(options.open_timeout_s * 1000);
  const int read_ms = static_cast<int>(options.read_timeout_s * 1000);
  std::error_code ec;
  if (path.rfind("device:", 0) == 0) {
    const std::string number = path.substr(7);
    if (number.empty() || number.size() > 4 ||
        number.find_first_not_of("0123456789") != std::string::npos) {
      return Status::Error(path + ": expected device:N with N a camera number");
    }
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
  if (IsUrlOrDevice(path)) {
    cv::VideoCapture capture(path, cv::CAP_FFMPEG,
                             {cv::CAP_PROP_OPEN_TIMEOUT_MSEC, open_ms,
                              cv::CAP_PROP_READ_TIMEOUT_MSEC, read_ms});
    if (!capture.isOpened()) {
      return Status::Error(path + ": cannot open the stream within " +
                           std::to_string(open_ms / 1000.0).substr(0, 4) +
                           " s (unreachable, nothing sent, or not a format OpenCV's FFmpeg "
                           "backend reads)");
    }
    *source = std::make_unique<CaptureSource>(path, std::move(capture), /*live=*/true, options);
    return Status::Ok();
  }
  if (fs::is_directory(path, ec)) return OpenFolder(path, source);
  if (!fs::exists(path, ec)) return Status::Error(path + ": no such file or folder");
  cv::VideoCapture capture(path, cv::CAP_FFMPEG);
  if (!capture.isOpened()) {
    return Status::Error(path + ": cannot open as a video (OpenCV FFmpeg backend)");
  }
  *source = std::make_unique<CaptureSource>(path, std::move(capture), /*live=*/false, options);
  return Status::Ok();
}

Status OpenVideoSource(const std::string& path, std::unique_ptr<VideoSource>* source) {
  return OpenVideoSource(path, VideoSourceOptions(), source);
}

}  // namespace fresco
