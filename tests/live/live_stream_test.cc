// End to end on loopback (issue 12): a synthetic capture streamed as H.264 over UDP by the
// `ffmpeg` program and its true poses sent as TUM lines over TCP with the tracker's clock
// 0.2 s ahead; `fresco run` paints it live, estimates the offset, records the session; the
// painted buffers are compared with replaying the capture from its files. Also: clear
// errors (exit 2, address named) for unreachable sources.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <future>
#include <string>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pipeline/core/poses.h"
#include "tests/live/loopback.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

using ::testing::HasSubstr;
using Json = nlohmann::json;

constexpr double kFps = 30.0;
constexpr double kOffsetS = 0.2;  // tracker clock minus video clock

// True once some process has bound UDP `port` (Fresco's stream receiver).
bool UdpPortBound(int port) {
  std::ifstream in("/proc/net/udp");
  char hex[8];
  std::snprintf(hex, sizeof hex, ":%04X ", port);
  std::string line;
  while (std::getline(in, line))
    if (line.find(hex) != std::string::npos && line.find(hex) < 30) return true;
  return false;
}

// Runs `fresco run PROJECT --out OUT [extra]` while `ffmpeg` streams the capture's frames
// to udp://127.0.0.1:PORT (H.264, lossless 4:4:4) at `rate` times their frame rate, once
// Fresco listens. Returns Fresco's result.
testing::CommandResult RunWhileStreaming(const std::string& project, const std::string& out,
                                         const std::vector<std::string>& extra,
                                         const std::string& frames_dir, int port, double rate) {
  std::vector<std::string> args = {"run", project, "--out", out, "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  auto run = std::async(std::launch::async, [&] { return testing::RunFresco(args); });
  // Start streaming once Fresco listens (it connects to the tracker first).
  for (int i = 0; i < 300 && !UdpPortBound(port); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_TRUE(UdpPortBound(port)) << "fresco never opened the stream";
  const std::string ffmpeg = "ffmpeg -hide_banner -loglevel error -readrate " +
                             std::to_string(rate) + " -framerate 30 -i " + frames_dir +
                             "/%06d.png -c:v libx264 -qp 0 -pix_fmt yuv444p -tune zerolatency "
                             "-g 15 -f mpegts 'udp://127.0.0.1:" +
                             std::to_string(port) + "?pkt_size=1316'";
  EXPECT_EQ(std::system(ffmpeg.c_str()), 0);
  return run.get();
}

bool HaveFfmpeg() { return std::system("ffmpeg -version >/dev/null 2>&1") == 0; }

Json ReadJson(const std::string& path) { return Json::parse(testing::ReadText(path)); }

// PSNR (dB) of the painted textures of two `fresco run` outputs over the texels painted in
// both, and the fraction of b's painted texels that a painted too.
void ComparePainted(const std::string& a_dir, const std::string& b_dir, double* psnr_db,
                    double* common_fraction) {
  double sq = 0;
  long long common = 0, painted_b = 0;
  for (int t = 0;; ++t) {
    const std::string name = "/painted_texture" + std::to_string(t) + ".png";
    const cv::Mat a = cv::imread(a_dir + name, cv::IMREAD_UNCHANGED);
    const cv::Mat b = cv::imread(b_dir + name, cv::IMREAD_UNCHANGED);
    if (a.empty() || b.empty()) break;
    EXPECT_EQ(a.size(), b.size()) << name;
    if (a.size() != b.size()) return;
    for (int y = 0; y < a.rows; ++y)
      for (int x = 0; x < a.cols; ++x) {
        const cv::Vec4b pa = a.at<cv::Vec4b>(y, x), pb = b.at<cv::Vec4b>(y, x);
        if (pb[3] == 0) continue;
        ++painted_b;
        if (pa[3] == 0) continue;
        ++common;
        for (int c = 0; c < 3; ++c) sq += (pa[c] - pb[c]) * double(pa[c] - pb[c]);
      }
  }
  const double mse = common > 0 ? sq / (3.0 * common) : 65025.0;
  *psnr_db = 10 * std::log10(65025.0 / std::max(mse, 1e-10));
  *common_fraction = painted_b > 0 ? double(common) / painted_b : 0;
}

TEST(LiveStreamTest, UdpVideoAndTcpPosesPaintLiveWithTheOffsetEstimated) {
  if (!HaveFfmpeg()) GTEST_SKIP() << "the ffmpeg program is not installed (apt-get install ffmpeg)";
  const std::string dir = testing::MakeTempDir("live");
  const int frames = 150;
  testing::CommandResult synth = testing::RunFresco(
      {"synth", "--scene", "builtin:cube-room", "--out", dir + "/synth", "--frames",
       std::to_string(frames), "--size", "160x120", "--supersample", "1", "--seed", "3"});
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  std::vector<PosedImage> truth;
  bool is_tum = false;
  ASSERT_TRUE(ReadPoses(dir + "/synth/truth/images.txt", &truth, &is_tum).ok());
  ASSERT_EQ(truth.size(), static_cast<size_t>(frames));
  std::sort(truth.begin(), truth.end(),
            [](const PosedImage& a, const PosedImage& b) { return a.name < b.name; });

  // The tracker: a TCP server sending each frame's true pose stamped on its own clock
  // (frame time + 0.2 s), paced at the frame rate.
  testing::PoseServer server;
  std::thread tracker([&] {
    const int c = server.Accept();
    if (c < 0) return;
    for (int i = 0; i < frames; ++i) {
      const std::string line =
          testing::TumLine(i / kFps + kOffsetS, truth[i].cam_from_world.Inverse());
      if (send(c, line.data(), line.size(), MSG_NOSIGNAL) < 0) break;
      std::this_thread::sleep_for(std::chrono::microseconds(static_cast<int>(1e6 / kFps)));
    }
    std::this_thread::sleep_for(std::chrono::seconds(1));
    close(c);
  });

  const int video_port = testing::FreeLoopbackPort(SOCK_DGRAM);
  const std::string texel = "0.02";
  Json project = {{"fresco", 1},
                  {"scene", dir + "/synth/scene.gltf"},
                  {"camera", dir + "/synth/camera.cameramodel"},
                  {"video", "udp://127.0.0.1:" + std::to_string(video_port)},
                  {"poses", server.Address()},
                  {"time_offset_s", 0.0},
                  {"pipeline", {{"texel_size_m", 0.02}}},
                  {"live",
                   {{"estimate_offset", true},
                    {"offset_search_s", 0.4},
                    {"offset_window_frames", 30},
                    {"open_timeout_s", 30},
                    {"read_timeout_s", 2},
                    {"queue_frames", 200}}}};
  testing::WriteText(dir + "/live.json", project.dump(2));
  const testing::CommandResult live =
      RunWhileStreaming(dir + "/live.json", dir + "/live_out", {"--record", dir + "/recorded"},
                        dir + "/synth/frames", video_port, 1.0);
  tracker.join();
  ASSERT_EQ(live.exit_code, 0) << live.err;

  const Json metrics = ReadJson(dir + "/live_out/metrics.json");
  const Json& l = metrics["live"];
  std::printf("live: %s\n", l.dump().substr(0, 700).c_str());
  EXPECT_TRUE(l["offset_estimated"].get<bool>()) << l["offset_estimate"]["note"];
  const double estimated = l["time_offset_s"].get<double>();
  EXPECT_NEAR(estimated, kOffsetS, 1.0 / kFps);
  EXPECT_EQ(l["video_clock"], "stream");
  EXPECT_GE(l["frames_received"].get<int>(), frames - 5);  // loopback UDP loses little
  // A queue longer than the capture: nothing is dropped (back-pressure: live_test), so the
  // comparison with the files below does not depend on the machine's speed.
  EXPECT_EQ(l["frames_dropped"].get<int>() + l["frames_held_dropped"].get<int>(), 0);
  EXPECT_THAT(l["end_reason"].get<std::string>(), HasSubstr("no frame within"));
  EXPECT_GT(metrics["frames_painted"].get<int>(), frames / 2);

  // Replay of the same capture from its files, same texel size.
  const testing::CommandResult replay =
      testing::RunFresco({"run", dir + "/synth/project.json", "--out", dir + "/file_out", "--set",
                          "pipeline.texel_size_m=" + texel, "--quiet"});
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  double psnr = 0, common = 0;
  ComparePainted(dir + "/live_out", dir + "/file_out", &psnr, &common);
  const Json file_metrics = ReadJson(dir + "/file_out/metrics.json");
  std::printf(
      "live vs files: PSNR %.2f dB over %.1f %% of the texels the files painted; "
      "coverage live %.4f files %.4f; offset %.4f s; painted %d of %d received, "
      "dropped %d\n",
      psnr, 100 * common, metrics["coverage"].get<double>(), file_metrics["coverage"].get<double>(),
      estimated, metrics["frames_painted"].get<int>(), l["frames_received"].get<int>(),
      l["frames_dropped"].get<int>());
  EXPECT_GT(psnr, 30.0);
  EXPECT_GT(common, 0.95);

  // The recording replays as a normal project, to what was painted live.
  const Json recorded_project = ReadJson(dir + "/recorded/project.json");
  EXPECT_EQ(recorded_project["video"], "frames/");
  const testing::CommandResult again = testing::RunFresco(
      {"run", dir + "/recorded/project.json", "--out", dir + "/recorded_out", "--quiet"});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  double psnr_rec = 0, common_rec = 0;
  ComparePainted(dir + "/recorded_out", dir + "/live_out", &psnr_rec, &common_rec);
  std::printf("recording replayed vs live: PSNR %.2f dB over %.1f %%\n", psnr_rec,
              100 * common_rec);
  EXPECT_EQ(ReadJson(dir + "/recorded_out/metrics.json")["frames_painted"],
            metrics["frames_painted"]);
  EXPECT_GT(psnr_rec, 45.0);
  EXPECT_GT(common_rec, 0.999);

  // A source faster than the painter: the same frames streamed at 20 times their rate,
  // poses from the recording's TUM file (matched by time), a queue of 4 frames. Memory
  // stays bounded by the queue; the frames the painter could not take are counted.
  project["video"] = "udp://127.0.0.1:" + std::to_string(video_port);
  project["poses"] = dir + "/recorded/poses.txt";
  project["live"] = {{"queue_frames", 4}, {"open_timeout_s", 30}, {"read_timeout_s", 2}};
  testing::WriteText(dir + "/fast.json", project.dump(2));
  const testing::CommandResult fast = RunWhileStreaming(dir + "/fast.json", dir + "/fast_out", {},
                                                        dir + "/synth/frames", video_port, 20.0);
  ASSERT_EQ(fast.exit_code, 0) << fast.err;
  const Json fast_metrics = ReadJson(dir + "/fast_out/metrics.json");
  const Json& f = fast_metrics["live"];
  EXPECT_LE(f["queue_high_water"].get<int>(), 4);
  EXPECT_EQ(f["frames_delivered"].get<int>() + f["frames_dropped"].get<int>(),
            f["frames_received"].get<int>());
  EXPECT_EQ(fast_metrics["frames"], f["frames_delivered"]);
  std::printf("20x rate, queue 4: %d received, %d painted, %d dropped, queue high water %d\n",
              f["frames_received"].get<int>(), fast_metrics["frames_painted"].get<int>(),
              f["frames_dropped"].get<int>(), f["queue_high_water"].get<int>());
}

TEST(LiveStreamTest, UnreachableSourcesExitTwoNamingTheAddress) {
  const std::string dir = testing::MakeTempDir("live_errors");
  testing::WriteText(dir + "/camera.txt", "1 PINHOLE 32 24 30 30 16 12\n");
  const std::string scene = testing::SourceDir() + "/projects/cube-room/scene.gltf";
  const int dead_tcp = testing::FreeLoopbackPort(SOCK_STREAM);
  const int silent_udp = testing::FreeLoopbackPort(SOCK_DGRAM);
  auto write_project = [&](const std::string& video, const std::string& poses) {
    Json p = {{"fresco", 1},
              {"scene", scene},
              {"camera", "camera.txt"},
              {"video", video},
              {"poses", poses},
              {"live", {{"connect_timeout_s", 0.3}, {"open_timeout_s", 1}}}};
    testing::WriteText(dir + "/p.json", p.dump());
    return dir + "/p.json";
  };
  // Nobody listens for the tracker connection.
  const std::string poses = "tcp://127.0.0.1:" + std::to_string(dead_tcp);
  testing::CommandResult r = testing::RunFresco(
      {"run", write_project("udp://127.0.0.1:" + std::to_string(silent_udp), poses), "--out",
       dir + "/out"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr(poses + ": cannot connect"));
  // Nothing is ever sent to the video port: opening times out.
  testing::WriteText(dir + "/poses.txt", "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
  const std::string video = "udp://127.0.0.1:" + std::to_string(silent_udp);
  r = testing::RunFresco({"run", write_project(video, "poses.txt"), "--out", dir + "/out"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr(video + ": cannot open the stream within 1.00 s"));
  // A camera that is not there.
  r = testing::RunFresco({"run", write_project("device:97", "poses.txt"), "--out", dir + "/out"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("device:97: cannot open the camera"));
}

}  // namespace
}  // namespace fresco
