// Video sources, streamed one frame at a time: a folder of images (sorted by file name), a
// video file (OpenCV's FFmpeg backend), or a live source ("device:N", a stream URL): the last
// two through the video module (video_capture_source.h).
#include "pipeline/core/video_source.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "pipeline/core/fresco_module.h"
#include "pipeline/core/image_io.h"
#include "pipeline/core/project.h"
#include "pipeline/core/video_capture_source.h"
#include "pipeline/core/video_frame_checks.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

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

// The video module's entry point (video_capture_source.h), loaded once; null if it does not
// load (`why` says why).
OpenCaptureSourceFunction VideoModule(std::string* why) {
  static std::once_flag once;
  static OpenCaptureSourceFunction function = nullptr;
  static std::string error;
  std::call_once(once, [] {
    function = reinterpret_cast<OpenCaptureSourceFunction>(
        LoadModuleSymbol(FRESCO_VIDEO_MODULE_FROM_BINDIR, FRESCO_VIDEO_MODULE_BUILD_PATH,
                         kOpenCaptureSourceSymbol, &error));
  });
  *why = error;
  return function;
}

Status OpenCapture(CaptureKind kind, const std::string& path, const VideoSourceOptions& options,
                   std::unique_ptr<VideoSource>* source) {
  std::string why;
  const OpenCaptureSourceFunction open = VideoModule(&why);
  if (!open)
    return Status::Failed(path + ": cannot read videos: Fresco's video module did not load (" +
                          why + ")");
  Status status;
  open(static_cast<int>(kind), path, options, source, &status);
  return status;
}

}  // namespace

Status OpenVideoSource(const std::string& path, const VideoSourceOptions& options,
                       std::unique_ptr<VideoSource>* source) {
  std::error_code ec;
  if (path.rfind("device:", 0) == 0) {
    const std::string number = path.substr(7);
    if (number.empty() || number.size() > 4 ||
        number.find_first_not_of("0123456789") != std::string::npos) {
      return Status::Error(path + ": expected device:N with N a camera number");
    }
    return OpenCapture(CaptureKind::kDevice, path, options, source);
  }
  if (IsUrlOrDevice(path)) return OpenCapture(CaptureKind::kStream, path, options, source);
  if (fs::is_directory(path, ec)) return OpenFolder(path, source);
  if (!fs::exists(path, ec)) return Status::Error(path + ": no such file or folder");
  return OpenCapture(CaptureKind::kFile, path, options, source);
}

Status OpenVideoSource(const std::string& path, std::unique_ptr<VideoSource>* source) {
  return OpenVideoSource(path, VideoSourceOptions(), source);
}

}  // namespace fresco
