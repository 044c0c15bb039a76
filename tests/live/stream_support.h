// Streaming helpers for the end-to-end live tests (tests/live/live_stream_test.cc for
// `fresco run`, tests/ui/live_runner_test.cc for the app's runner): a capture's frames sent
// by the `ffmpeg` program (to a local UDP port, served over HTTP, pushed over RTSP), its
// true poses sent as a tracker would over TCP, and the painted buffers of two runs compared.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "pipeline/core/poses.h"
#include "tests/live/loopback.h"
#include "tests/test_support.h"

namespace fresco::testing {

inline bool HaveFfmpeg() { return std::system("ffmpeg -version >/dev/null 2>&1") == 0; }

// True when /proc/net/TABLE ("udp", "tcp") lists a socket on local port `port` in `state`
// (its hex code; "" = any).
inline bool SocketListed(const std::string& table, int port, const std::string& state) {
  std::ifstream in("/proc/net/" + table);
  char suffix[8];
  std::snprintf(suffix, sizeof suffix, ":%04X", port);
  std::string line, slot, local, remote, st;
  std::getline(in, line);  // the header
  while (in >> slot >> local >> remote >> st) {
    std::getline(in, line);
    if (local.size() > 5 && local.compare(local.size() - 5, 5, suffix) == 0 &&
        (state.empty() || st == state))
      return true;
  }
  return false;
}

// Waits (up to 30 s) until `condition` holds; false when it never does.
inline bool WaitUntil(const std::function<bool()>& condition) {
  for (int i = 0; i < 300 && !condition(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  return condition();
}

// True once some process has bound UDP `port` (Fresco's stream receiver).
inline bool UdpPortBound(int port) { return SocketListed("udp", port, ""); }

// Waits (up to 30 s) until Fresco listens on UDP `port`; false when it never does.
inline bool WaitUdpPortBound(int port) {
  return WaitUntil([port] { return UdpPortBound(port); });
}

// Waits (up to 30 s) until something listens on TCP `port` (state 0A: LISTEN).
inline bool WaitTcpPortListening(int port) {
  return WaitUntil([port] { return SocketListed("tcp", port, "0A"); });
}

// The `ffmpeg` command that sends FRAMES_DIR/%06d.png (H.264, lossless 4:4:4, MPEG-TS
// unless `format` says otherwise) to OUTPUT at `rate` times 30 fps. `pad_frames` copies of
// the last frame are appended: a receiver gets a frame only once the next one starts, and a
// stream that never signals its end (UDP) keeps its last frames, so padding delivers all
// the real ones. `output_options` go before OUTPUT (e.g. "-listen 1" for an HTTP server).
inline std::string FfmpegStreamCommand(const std::string& frames_dir, const std::string& output,
                                       double rate, int pad_frames,
                                       const std::string& output_options = "",
                                       const std::string& format = "mpegts") {
  std::string command = "timeout 120 ffmpeg -hide_banner -loglevel error -readrate " +
                        std::to_string(rate) + " -framerate 30 -i " + frames_dir + "/%06d.png";
  if (pad_frames > 0)
    command += " -vf tpad=stop=" + std::to_string(pad_frames) + ":stop_mode=clone";
  return command +
         " -c:v libx264 -qp 0 -pix_fmt yuv444p -tune zerolatency -g 15 -f " + format + " " +
         output_options + " '" + output + "'";
}

// Streams FRAMES_DIR/%06d.png to udp://127.0.0.1:PORT with the `ffmpeg` program (see
// FfmpegStreamCommand); returns when all are sent. True on success.
inline bool StreamFrames(const std::string& frames_dir, int port, double rate,
                         int pad_frames = 0) {
  const std::string url = "udp://127.0.0.1:" + std::to_string(port) + "?pkt_size=1316";
  return std::system(FfmpegStreamCommand(frames_dir, url, rate, pad_frames).c_str()) == 0;
}

// A hand-held capture of the cube room (`fresco synth`, 160x120, seed 3 unless told) in
// DIR; returns its true poses in frame order (empty on failure).
inline std::vector<PosedImage> MakeStreamCapture(const std::string& dir, int frames,
                                                 int seed = 3) {
  const CommandResult synth = RunFresco({"synth", "--scene", "builtin:cube-room", "--out", dir,
                                         "--frames", std::to_string(frames), "--size", "160x120",
                                         "--supersample", "1", "--seed", std::to_string(seed)});
  EXPECT_EQ(synth.exit_code, 0) << synth.err;
  std::vector<PosedImage> truth;
  bool is_tum = false;
  EXPECT_TRUE(ReadPoses(dir + "/truth/images.txt", &truth, &is_tum).ok()) << dir;
  std::sort(truth.begin(), truth.end(),
            [](const PosedImage& a, const PosedImage& b) { return a.name < b.name; });
  return truth;
}

// Two hand-held captures of the room for the two-camera tests (MakeStreamCapture): DIR/a
// (seed 3) and DIR/b (seed 8), each with its true poses and a free loopback UDP port for its
// video.
struct TwoStreamCaptures {
  std::string dir[2];
  std::vector<PosedImage> truth[2];
  int port[2] = {0, 0};
  std::string Udp(int s) const { return "udp://127.0.0.1:" + std::to_string(port[s]); }
};
inline TwoStreamCaptures MakeTwoStreamCaptures(const std::string& dir, int frames) {
  TwoStreamCaptures c;
  for (int s = 0; s < 2; ++s) {
    c.dir[s] = dir + (s == 0 ? "/a" : "/b");
    c.truth[s] = MakeStreamCapture(c.dir[s], frames, s == 0 ? 3 : 8);
    EXPECT_EQ(c.truth[s].size(), static_cast<size_t>(frames)) << c.dir[s];
    c.port[s] = FreeLoopbackPort(SOCK_DGRAM);
  }
  return c;
}

// Sends both captures' frames (StreamFrames), each once Fresco listens on its port (OpenCV
// opens one stream at a time: the second port opens once the first stream's packets came);
// returns when both are sent, true when both were.
inline bool SendTwoStreams(const TwoStreamCaptures& c, double rate, int pad_frames) {
  std::future<bool> sent[2];
  for (int s = 0; s < 2; ++s)
    sent[s] = std::async(std::launch::async, [&c, s, rate, pad_frames] {
      return WaitUdpPortBound(c.port[s]) &&
             StreamFrames(c.dir[s] + "/frames", c.port[s], rate, pad_frames);
    });
  bool ok = true;
  for (int s = 0; s < 2; ++s) {
    const bool one = sent[s].get();
    EXPECT_TRUE(one) << "sending " << c.Udp(s);
    ok = ok && one;
  }
  return ok;
}

// A live project over the capture in CAPTURE_DIR: video from VIDEO (StreamProject:
// udp://127.0.0.1:VIDEO_PORT), poses from POSES; texel 0.02 m; the offset estimated
// (window 30 frames, +-0.4 s); a queue longer than the capture (nothing dropped: the
// comparison with the files does not depend on the machine's speed).
inline nlohmann::json StreamProjectFrom(const std::string& capture_dir, const std::string& video,
                                        const std::string& poses) {
  return {{"fresco", 1},
          {"scene", capture_dir + "/scene.gltf"},
          {"camera", capture_dir + "/camera.cameramodel"},
          {"video", video},
          {"poses", poses},
          {"time_offset_s", 0.0},
          {"pipeline", {{"texel_size_m", 0.02}}},
          {"live",
           {{"estimate_offset", true},
            {"offset_search_s", 0.4},
            {"offset_window_frames", 30},
            {"open_timeout_s", 30},
            {"read_timeout_s", 2},
            {"queue_frames", 200}}}};
}
inline nlohmann::json StreamProject(const std::string& capture_dir, int video_port,
                                    const std::string& poses) {
  return StreamProjectFrom(capture_dir, "udp://127.0.0.1:" + std::to_string(video_port), poses);
}

// The tracker: accepts one connection on `server` and sends frame i's true pose stamped
// i / fps + offset_s on its own clock, paced at `fps`; then waits a second and closes.
inline void ServeTrack(PoseServer* server, const std::vector<PosedImage>& truth, double fps,
                       double offset_s) {
  const int c = server->Accept();
  if (c < 0) return;
  for (size_t i = 0; i < truth.size(); ++i) {
    const std::string line = TumLine(i / fps + offset_s, truth[i].cam_from_world.Inverse());
    if (send(c, line.data(), line.size(), MSG_NOSIGNAL) < 0) break;
    std::this_thread::sleep_for(std::chrono::microseconds(static_cast<int>(1e6 / fps)));
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));
  close(c);
}

// PSNR (dB) of two runs' painted buffers (BGRA, alpha 0 = never painted) over the texels
// painted in both, and the fraction of b's painted texels that a painted too.
inline void ComparePaintedBuffers(const std::vector<cv::Mat>& a, const std::vector<cv::Mat>& b,
                                  double* psnr_db, double* common_fraction) {
  double sq = 0;
  long long common = 0, painted_b = 0;
  EXPECT_EQ(a.size(), b.size());
  for (size_t t = 0; t < std::min(a.size(), b.size()); ++t) {
    EXPECT_EQ(a[t].size(), b[t].size()) << "buffer " << t;
    if (a[t].size() != b[t].size()) return;
    for (int y = 0; y < a[t].rows; ++y)
      for (int x = 0; x < a[t].cols; ++x) {
        const cv::Vec4b pa = a[t].at<cv::Vec4b>(y, x), pb = b[t].at<cv::Vec4b>(y, x);
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

}  // namespace fresco::testing
