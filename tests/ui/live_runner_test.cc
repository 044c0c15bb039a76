// The app paints live sources, headless on loopback: a synthetic capture streamed as
// H.264 over UDP by the `ffmpeg` program and its true poses over TCP (tracker clock 0.2 s
// ahead); the app's PipelineRunner paints it through the live core, its snapshot and the
// Pipeline panel show the sources' state (frames received, stalled, ended, the estimated
// offset), the session is recorded and the recording replays from files to the same
// buffers. A dead source and a malformed pose feed are reported and the runner keeps working.
#include <sys/socket.h>

#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/live/loopback.h"
#include "tests/live/stream_support.h"
#include "tests/test_support.h"
#include "tests/ui/headless_ui.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
using Json = nlohmann::json;

constexpr double kFps = 30.0;
constexpr double kOffsetS = 0.2;  // tracker clock minus video clock

// The panels drawn headless over the runner's latest snapshot; returns the Pipeline panel's
// report (what it shows).
std::map<std::string, std::string> DrawPanels(AppState* state, PipelineRunner* runner) {
  testing::NullTextures textures;
  testing::NullViewport viewport;
  testing::ImGuiHeadless imgui;
  UiContext ui{state, runner, nullptr, &textures, &viewport, runner->Snapshot(), false};
  auto panels = MakePanels();
  for (int i = 0; i < 2; ++i) imgui.Frame(ui, panels);
  for (const auto& panel : panels)
    if (std::string(panel->Title()) == "Pipeline") return panel->Report();
  ADD_FAILURE() << "no Pipeline panel";
  return {};
}

// Painted buffers of a snapshot (BGRA).
std::vector<cv::Mat> Painted(const RunnerSnapshot& snap) {
  return snap.painted ? *snap.painted : std::vector<cv::Mat>();
}

// After a live source failed, the runner still works: a project from files paints up to
// `frame`.
void ExpectFilesStillPaint(PipelineRunner* runner, const std::string& project_json, int frame) {
  AppState files;
  ASSERT_TRUE(files.Open(project_json).ok());
  runner->Restart(files.project);
  runner->Seek(frame);
  runner->WaitIdle();
  const auto snap = runner->Snapshot();
  EXPECT_EQ(snap->frame, frame);
  EXPECT_EQ(snap->status, "paused");
  EXPECT_FALSE(snap->live.active);
  EXPECT_GT(snap->coverage, 0.0);
}

TEST(UiLive, PaintsAStreamShowsItsStateAndRecordsASessionThatReplays) {
  if (!testing::HaveFfmpeg())
    GTEST_SKIP() << "the ffmpeg program is not installed (apt-get install ffmpeg)";
  const std::string dir = testing::MakeTempDir("ui_live");
  const int frames = 90;
  const std::vector<PosedImage> truth = testing::MakeStreamCapture(dir + "/synth", frames);
  ASSERT_EQ(truth.size(), static_cast<size_t>(frames));
  testing::PoseServer server;
  std::thread tracker(testing::ServeTrack, &server, truth, kFps, kOffsetS);

  const int video_port = testing::FreeLoopbackPort(SOCK_DGRAM);
  Json project = testing::StreamProject(dir + "/synth", video_port, server.Address());
  project["live"]["read_timeout_s"] = 3;
  testing::WriteText(dir + "/live.json", project.dump(2));
  AppState state;
  ASSERT_TRUE(state.Open(dir + "/live.json").ok());

  PipelineRunner runner;
  runner.Restart(state.project);  // connects to the tracker, then waits for the stream
  runner.Record(dir + "/recorded");
  runner.Play();
  ASSERT_TRUE(testing::WaitUdpPortBound(video_port)) << "the runner never opened the stream";
  ASSERT_TRUE(testing::StreamFrames(dir + "/synth/frames", video_port, 1.0));
  // The stream has stopped: within read_timeout_s (3 s) the runner reports it stalled (no
  // frame for more than a second), then ended; it never stops publishing meanwhile.
  bool saw_stalled = false;
  std::string stalled_problem;
  for (int i = 0; i < 200 && !saw_stalled; ++i) {
    const auto snap = runner.Snapshot();
    if (snap->live.state == "stalled") saw_stalled = true, stalled_problem = snap->live.problem;
    if (snap->live.state == "ended") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  runner.WaitIdle();  // stops playing when the video ends
  tracker.join();
  const auto live = runner.Snapshot();
  const LiveStatus& l = live->live;
  std::printf(
      "app live: %lld received, %lld delivered, %lld dropped, %lld without pose; offset %.4f s "
      "(estimated %d, score %.2f); pose lag %.3f s; recorded %d frames; coverage %.4f; "
      "status '%s'\n",
      l.frames.frames_received, l.frames.frames_delivered, l.frames.frames_dropped, l.frames.frames_without_pose,
      l.frames.time_offset_s, l.frames.offset_estimated, l.frames.estimate.score, l.pose_lag_s, l.recorded_frames,
      live->coverage, live->status.c_str());
  ASSERT_TRUE(l.active);
  EXPECT_TRUE(saw_stalled) << "never reported the stalled stream";
  EXPECT_THAT(stalled_problem, HasSubstr("video stalled: no frame for"));
  EXPECT_EQ(l.state, "ended");
  // UDP carries no end of stream: the sender finishing reads as a stall.
  EXPECT_THAT(live->status, StartsWith("live video ended: stalled: no frame within 3.0 s after " +
                                       std::to_string(l.frames.frames_received) + " frames"));
  EXPECT_THAT(live->status, HasSubstr("does not signal the end of a stream"));
  EXPECT_THAT(l.problem, HasSubstr("live video ended"));
  EXPECT_GE(l.frames.frames_received, frames - 5);  // loopback UDP loses little
  EXPECT_EQ(l.frames.frames_dropped, 0);            // the queue is longer than the capture
  EXPECT_EQ(l.frames.frames_delivered, l.frames.frames_received);
  EXPECT_TRUE(l.frames.offset_estimated) << l.frames.estimate.note;
  EXPECT_NEAR(l.frames.time_offset_s, kOffsetS, 1.0 / kFps);
  EXPECT_TRUE(l.pose_lag_known);
  EXPECT_EQ(l.feed.poses, frames);
  const int painted = static_cast<int>(l.frames.frames_delivered - l.frames.frames_without_pose);
  EXPECT_GT(painted, frames / 2);
  EXPECT_EQ(static_cast<int>(live->frames_painted.size()), painted);
  EXPECT_EQ(l.frames_painted, painted);
  ASSERT_EQ(live->live_paths.size(), 1u);  // the 3D view's path
  EXPECT_EQ(static_cast<int>(live->live_paths[0].size()), painted);
  EXPECT_GT(live->coverage, 0.5);
  // The recording stopped with the stream and wrote a project.
  EXPECT_FALSE(l.recording);
  EXPECT_EQ(l.recorded_frames, painted);
  EXPECT_EQ(l.recorded_project, dir + "/recorded/project.json");
  EXPECT_TRUE(l.record_error.empty()) << l.record_error;
  // With the tracker's own samples around it (PoseFeed::PosesBetween: all 90 lie within
  // max_pose_gap_s of the recorded frames).
  std::vector<PosedImage> tracker_poses;
  bool is_tum = false;
  ASSERT_TRUE(ReadPoses(dir + "/recorded/tracker_poses.txt", &tracker_poses, &is_tum).ok());
  EXPECT_TRUE(is_tum);
  EXPECT_EQ(tracker_poses.size(), static_cast<size_t>(frames));

  // The Pipeline panel shows it.
  const auto report = DrawPanels(&state, &runner);
  EXPECT_EQ(report.at("live.state"), "ended");
  EXPECT_EQ(report.at("live.frames_received"), std::to_string(l.frames.frames_received));
  EXPECT_EQ(report.at("live.frames_dropped"), "0");
  EXPECT_EQ(report.at("live.frames_painted"), std::to_string(painted));
  EXPECT_THAT(report.at("live.time_offset"), HasSubstr("(estimated"));

  // The recording, opened in the app, replays from files to the buffers painted live.
  AppState replay_state;
  ASSERT_TRUE(replay_state.Open(l.recorded_project).ok());
  EXPECT_EQ(replay_state.project.video, "frames/");
  PipelineRunner replay;
  replay.Restart(replay_state.project);
  replay.Seek(1 << 20);  // to the end
  replay.WaitIdle();
  const auto again = replay.Snapshot();
  EXPECT_EQ(again->status, "end of video");
  EXPECT_FALSE(again->live.active);
  EXPECT_EQ(again->frames_painted.size(), live->frames_painted.size());
  double psnr = 0, common = 0;
  testing::ComparePaintedBuffers(Painted(*again), Painted(*live), &psnr, &common);
  std::printf("recording replayed in the app vs painted live: PSNR %.2f dB over %.2f %%\n", psnr,
              100 * common);
  EXPECT_GT(psnr, 45.0);
  EXPECT_GT(common, 0.999);
}

// Two cameras live (UDP video and a TCP tracker each): the app paints both streams' frames
// into one model, as `fresco run` paints both from their files (the same coverage), shows
// each stream's latest input, and says that recording needs one stream.
TEST(UiLive, TwoLiveStreamsPaintOneModelAsTheRunDoes) {
  if (!testing::HaveFfmpeg())
    GTEST_SKIP() << "the ffmpeg program is not installed (apt-get install ffmpeg)";
  const std::string dir = testing::MakeTempDir("ui_live_two");
  const int frames = 60;
  const testing::TwoStreamCaptures c = testing::MakeTwoStreamCaptures(dir, frames);
  testing::PoseServer servers[2];
  std::thread trackers[2];
  Json live_streams = Json::array(), file_streams = Json::array();
  for (int s = 0; s < 2; ++s) {
    trackers[s] = std::thread(testing::ServeTrack, &servers[s], c.truth[s], kFps, kOffsetS);
    live_streams.push_back({{"camera", c.dir[s] + "/camera.cameramodel"},
                            {"video", c.Udp(s)},
                            {"poses", servers[s].Address()},
                            {"time_offset_s", kOffsetS}});
    file_streams.push_back({{"camera", c.dir[s] + "/camera.cameramodel"},
                            {"video", c.dir[s] + "/frames/"},
                            {"poses", c.dir[s] + "/sparse/images.txt"}});
  }
  const Json project = {
      {"fresco", 2},
      {"scene", dir + "/a/scene.gltf"},
      {"streams", live_streams},
      {"pipeline", {{"texel_size_m", 0.02}}},
      {"live", {{"open_timeout_s", 30}, {"read_timeout_s", 2}, {"queue_frames", 200}}}};
  testing::WriteText(dir + "/live.json", project.dump(2));
  Json files = project;
  files["streams"] = file_streams;
  files.erase("live");
  testing::WriteText(dir + "/files.json", files.dump(2));

  AppState state;
  ASSERT_TRUE(state.Open(dir + "/live.json").ok());
  PipelineRunner runner;
  runner.Restart(state.project);  // connects to both trackers, then waits for the streams
  runner.Play();
  testing::SendTwoStreams(c, 1.0, 2);
  runner.WaitIdle();  // stops playing when both videos ended
  for (std::thread& tracker : trackers) tracker.join();
  const auto live = runner.Snapshot();
  std::printf("app, two live streams: %zu frames painted, coverage %.4f, status '%s'\n",
              live->frames_painted.size(), live->coverage, live->status.c_str());
  ASSERT_TRUE(live->live.active);
  EXPECT_EQ(live->live.streams, 2);
  EXPECT_EQ(live->run.streams.size(), 2u);
  ASSERT_EQ(live->live_paths.size(), 2u);  // each stream's path in the 3D view, apart
  for (int s = 0; s < 2 && live->run.streams.size() == 2; ++s) {
    EXPECT_EQ(live->run.streams[s].painted, frames) << "stream " << s;
    EXPECT_FALSE(live->stream_frames[s].empty()) << "stream " << s << "'s input";
    EXPECT_EQ(static_cast<int>(live->live_paths[s].size()), frames) << "stream " << s;
  }
  EXPECT_EQ(static_cast<int>(live->frames_painted.size()), 2 * frames);
  EXPECT_THAT(live->status, HasSubstr("stream 0: live video ended"));
  EXPECT_THAT(live->status, HasSubstr("stream 1: live video ended"));
  const auto report = DrawPanels(&state, &runner);
  EXPECT_EQ(report.count("live.state"), 1u);

  const testing::CommandResult run =
      testing::RunFresco({"run", dir + "/files.json", "--out", dir + "/out", "--quiet"});
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json metrics = Json::parse(testing::ReadText(dir + "/out/metrics.json"));
  EXPECT_NEAR(live->coverage, metrics["coverage"].get<double>(), 0.001);
}

TEST(UiLive, DeadSourcesAreReportedAndTheRunnerKeepsWorking) {
  const std::string dir = testing::MakeTempDir("ui_live_dead");
  testing::WriteText(dir + "/camera.txt", "1 PINHOLE 32 24 30 30 16 12\n");
  testing::WriteText(dir + "/poses.txt", "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
  const std::string scene = testing::SourceDir() + "/projects/cube-room/scene.gltf";
  const int dead_tcp = testing::FreeLoopbackPort(SOCK_STREAM);
  const int silent_udp = testing::FreeLoopbackPort(SOCK_DGRAM);
  auto open = [&](const std::string& video, const std::string& poses) {
    const Json p = {{"fresco", 1},
                    {"scene", scene},
                    {"camera", "camera.txt"},
                    {"video", video},
                    {"poses", poses},
                    {"pipeline", {{"texel_size_m", 0.05}}},
                    {"live", {{"connect_timeout_s", 0.3}, {"open_timeout_s", 1}}}};
    testing::WriteText(dir + "/p.json", p.dump());
    AppState state;
    EXPECT_TRUE(state.Open(dir + "/p.json").ok());
    return state.project;
  };
  PipelineRunner runner;
  // Nobody listens for the tracker connection.
  const std::string tracker = "tcp://127.0.0.1:" + std::to_string(dead_tcp);
  const std::string video = "udp://127.0.0.1:" + std::to_string(silent_udp);
  runner.Restart(open(video, tracker));
  runner.Play();
  runner.WaitIdle();
  auto snap = runner.Snapshot();
  EXPECT_THAT(snap->status, StartsWith("error: " + tracker + ": cannot connect"));
  EXPECT_TRUE(snap->live.active);
  EXPECT_EQ(snap->live.state, "error");
  EXPECT_THAT(snap->live.problem, HasSubstr(tracker + ": cannot connect"));
  EXPECT_FALSE(snap->playing);
  // Nothing is ever sent to the video port: opening times out.
  runner.Restart(open(video, "poses.txt"));
  runner.Play();
  runner.WaitIdle();
  snap = runner.Snapshot();
  EXPECT_THAT(snap->status, HasSubstr(video + ": cannot open the stream within 1.00 s"));
  EXPECT_EQ(snap->live.state, "error");
  // The runner is still there: a project from files paints.
  testing::MakeStreamCapture(dir + "/capture", 4);
  ExpectFilesStillPaint(&runner, dir + "/capture/project.json", 3);
}

TEST(UiLive, AMalformedPoseFeedIsReportedAndTheRunnerKeepsWorking) {
  const std::string dir = testing::MakeTempDir("ui_live_feed");
  const std::vector<PosedImage> truth = testing::MakeStreamCapture(dir + "/synth", 6);
  ASSERT_EQ(truth.size(), 6u);
  // The tracker sends three good lines, then one that is not a pose.
  testing::PoseServer server;
  std::string lines;
  for (int i = 0; i < 3; ++i)
    lines += testing::TumLine(i / kFps, truth[i].cam_from_world.Inverse());
  std::thread tracker([&] { server.ServeOnce(lines + "0 1 2 oops\n"); });
  // Frames from the capture's files, poses from the feed (matched by time).
  Json project = testing::StreamProject(dir + "/synth", 0, server.Address());
  project["video"] = dir + "/synth/frames/";
  project["live"] = {{"connect_timeout_s", 5}, {"pose_wait_s", 0.5}};
  testing::WriteText(dir + "/feed.json", project.dump(2));
  AppState state;
  ASSERT_TRUE(state.Open(dir + "/feed.json").ok());
  PipelineRunner runner;
  runner.Restart(state.project);
  runner.Play();
  runner.WaitIdle();
  tracker.join();
  auto snap = runner.Snapshot();
  std::printf("malformed feed: status '%s'\n", snap->status.c_str());
  EXPECT_THAT(snap->status, StartsWith("error: " + server.Address() + ":4: "));
  EXPECT_THAT(snap->status, HasSubstr("(8 fields)"));
  EXPECT_EQ(snap->live.state, "error");
  EXPECT_EQ(snap->live.problem, snap->status);
  EXPECT_FALSE(snap->playing);
  // The runner is still there: the same capture from its files paints.
  ExpectFilesStillPaint(&runner, dir + "/synth/project.json", 5);
}

}  // namespace
}  // namespace fresco
