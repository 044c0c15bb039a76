#include "tests/run/bad_captures.h"

#include <filesystem>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/test_support.h"

namespace fresco::testing {
namespace {

namespace fs = std::filesystem;

// images.txt with the pose of `name` changed by `edit` (its points line too when the edit
// returns "" for the pose line: the pose is dropped).
void EditPose(const std::string& images_txt, const std::string& name,
              std::string (*edit)(const std::string& line)) {
  std::istringstream in(ReadText(images_txt));
  std::string out, line;
  bool drop_next = false;
  while (std::getline(in, line)) {
    if (drop_next) {
      drop_next = false;
      continue;
    }
    const bool is_pose = !line.empty() && line[0] != '#' && line.size() > name.size() &&
                         line.compare(line.size() - name.size(), name.size(), name) == 0;
    if (is_pose) {
      line = edit(line);
      if (line.empty()) {
        drop_next = true;  // the (empty) points line that follows
        continue;
      }
    }
    out += line + "\n";
  }
  WriteText(images_txt, out);
}

// "ID QW QX QY QZ TX TY TZ CAMERA_ID NAME" with CAMERA_ID 7.
std::string WithCamera7(const std::string& line) {
  std::istringstream fields(line);
  std::vector<std::string> f;
  for (std::string x; fields >> x;) f.push_back(x);
  f[8] = "7";
  std::string joined;
  for (const std::string& x : f) joined += (joined.empty() ? "" : " ") + x;
  return joined;
}

std::string Dropped(const std::string&) { return ""; }

}  // namespace

std::string GoodCaptureDir() {
  static const std::string dir = [] {
    const std::string d = MakeTempDir("job-good") + "/capture";
    const CommandResult r =
        RunFresco({"synth", "--scene", "builtin:cube-room", "--out", d, "--frames",
                   std::to_string(kGoodCaptureFrames), "--size", "160x120", "--seed", "3"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return d;
  }();
  return dir;
}

std::string MakeBadCapture(BadCapture how) {
  const std::string dir = MakeTempDir("job-bad") + "/capture";
  fs::copy(GoodCaptureDir(), dir, fs::copy_options::recursive);
  switch (how) {
    case BadCapture::kFramesSmallerThanCamera:
      for (const auto& entry : fs::directory_iterator(dir + "/frames"))
        cv::imwrite(entry.path().string(), cv::Mat(60, 80, CV_8UC3, cv::Scalar(1, 2, 3)));
      break;
    case BadCapture::kUnknownCameraId:
      EditPose(dir + "/sparse/images.txt", "000003.png", WithCamera7);
      break;
    case BadCapture::kMissingPose:
      EditPose(dir + "/sparse/images.txt", "000003.png", Dropped);
      break;
    case BadCapture::kCorruptImage:
      WriteText(dir + "/frames/000005.png", "this is not a PNG");
      break;
  }
  return dir + "/project.json";
}

std::string MakeTwoStreamCapture() {
  const std::string dir = fs::path(MakeBadCapture(BadCapture::kMissingPose)).parent_path();
  fs::create_directories(dir + "/good");
  fs::copy_file(GoodCaptureDir() + "/sparse/images.txt", dir + "/good/images.txt");
  nlohmann::json project = nlohmann::json::parse(ReadText(dir + "/project.json"));
  for (const char* key : {"camera", "video", "poses", "time_offset_s"}) project.erase(key);
  project["fresco"] = 2;
  project["streams"] = {
      {{"camera", "camera.cameramodel"}, {"video", "frames/"}, {"poses", "good/images.txt"}},
      {{"camera", "camera.cameramodel"}, {"video", "frames/"}, {"poses", "sparse/images.txt"}}};
  WriteText(dir + "/two.json", project.dump(2));
  return dir + "/two.json";
}

LiveBadCapture MakeLiveSmallFramesCapture(int pose_port) {
  const std::string project_json = MakeBadCapture(BadCapture::kFramesSmallerThanCamera);
  const std::string dir = fs::path(project_json).parent_path().string();
  LiveBadCapture c;
  bool is_tum = false;
  EXPECT_TRUE(ReadPoses(dir + "/sparse/images.txt", &c.truth, &is_tum).ok());
  nlohmann::json live = nlohmann::json::parse(ReadText(project_json));
  live["poses"] = "tcp://127.0.0.1:" + std::to_string(pose_port);
  live["live"] = {{"estimate_offset", true}, {"offset_window_frames", 8},
                  {"offset_search_s", 0.1},  {"connect_timeout_s", 10},
                  {"read_timeout_s", 2},     {"queue_frames", 50}};
  c.project = dir + "/live.json";
  WriteText(c.project, live.dump(2));
  c.first_frame_error = dir + "/frames/: frame '000000.png' is 80x60 but the camera is 160x120";
  return c;
}

std::string Describe(BadCapture how) {
  switch (how) {
    case BadCapture::kFramesSmallerThanCamera:
      return "frames smaller than the camera";
    case BadCapture::kUnknownCameraId:
      return "a pose naming an unknown camera";
    case BadCapture::kMissingPose:
      return "a frame without a pose";
    case BadCapture::kCorruptImage:
      return "a corrupt image file";
  }
  return "?";
}

std::vector<BadCapture> AllBadCaptures() {
  return {BadCapture::kFramesSmallerThanCamera, BadCapture::kUnknownCameraId,
          BadCapture::kMissingPose, BadCapture::kCorruptImage};
}

}  // namespace fresco::testing
