// Endless streams: Fresco runs for hours on live video, so painting must not
// grow without bound. A synthetic stream of 10,000 small frames (160x120, rendered on the
// fly by the synthetic renderer, never written to disk) goes through the real PaintSession
// with every stage on (robust background with a mover, refinement with consensus anchoring
// on noisy poses, debug images on some frames), and the process's resident memory (VmRSS
// from /proc/self/status) is sampled as it goes: after the warm-up (frame 1000) it must stay
// flat. A leak of 400 bytes a frame would add 3.6 MB over the 9,000 frames measured.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/paint/paint_session.h"
#include "pipeline/synth/procedural_scenes.h"
#include "pipeline/synth/synthesize.h"
#include "tests/paint/room_capture.h"

namespace fresco {
namespace {

// Resident memory of this process, kB (VmRSS in /proc/self/status); -1 when unreadable.
long ResidentKb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

constexpr int kFrames = 10000;
constexpr int kWarmupFrames = 1000;
constexpr int kSampleEvery = 500;
constexpr long kMaxGrowthKb = 4 * 1024;  // after the warm-up

TEST(EndlessStream, ResidentMemoryStaysFlatOverTenThousandFrames) {
  ASSERT_GT(ResidentKb(), 0) << "/proc/self/status has no VmRSS";
  CubeRoomOptions room;
  room.procedural_texture_px = 128;
  Scene scene;
  ASSERT_TRUE(MakeCubeRoomScene(room, &scene).ok());

  // A handheld camera going round the room 20 times, a mover, and noisy given poses.
  SynthOptions synth = testing::HandheldRoomCapture(kFrames, 0.4);
  synth.width = 160;
  synth.height = 120;
  synth.supersample = 1;
  synth.turns = 20;
  synth.random_movers = 1;
  synth.pose_noise_deg = 0.2;
  synth.pose_noise_m = 0.01;
  synth.threads = 1;  // the painting takes the other core
  SynthCapture plan;
  ASSERT_TRUE(PlanSynthCapture(scene, synth, &plan).ok());
  ASSERT_EQ(plan.given_poses.size(), static_cast<size_t>(kFrames));

  PaintSessionInputs inputs;
  inputs.scene = &scene;
  inputs.pipeline.max_buffer_texels = 64 * 64;  // tiny buffers: the test is about memory
  inputs.pipeline.background.mode = BackgroundMode::kRobust;
  inputs.pipeline.refine.mode = RefineMode::kRobust;
  inputs.pipeline.refine.every_n_frames = 4;
  inputs.typical_camera = &plan.camera;
  for (int i = 0; i < kFrames; i += 100)
    inputs.expected_poses.push_back(plan.given_poses[i].cam_from_world);
  std::unique_ptr<PaintSession> session;
  ASSERT_TRUE(PaintSession::Create(inputs, &session).ok());

  std::vector<long> rss_kb;  // at frames 0, kSampleEvery, ...
  int painted = 0, debug_frames = 0, refined = 0;
  FrameReport report;
  const Status status = RenderSynthFrames(scene, synth, plan, [&](int i, const cv::Mat& bgr) {
    Frame frame;
    frame.index = i;
    frame.name = SynthFrameName(i);
    frame.bgr = bgr;
    // Debug images on some frames, as the app asks for the frames it shows.
    const bool debug = i % 97 == 0;
    session->set_debug_images(debug);
    session->PaintFrame(frame, plan.camera, plan.given_poses[i].cam_from_world, &report);
    painted += report.painted;
    debug_frames += debug && !report.stages.empty() && !report.stages[0].images.empty();
    for (const StageReport& stage : report.stages) refined += stage.name == "refine";
    if (i % kSampleEvery == 0) rss_kb.push_back(ResidentKb());
    return Status::Ok();
  });
  ASSERT_TRUE(status.ok()) << status.message();
  rss_kb.push_back(ResidentKb());

  EXPECT_EQ(painted, kFrames);
  EXPECT_GT(debug_frames, 50);
  EXPECT_GE(refined, kFrames / 4);
  EXPECT_GT(session->Coverage(), 0.3);
  std::string series;
  for (size_t k = 0; k < rss_kb.size(); ++k)
    series += (k ? ", " : "") + std::to_string(rss_kb[k] / 1024.0).substr(0, 5);
  const long at_warmup = rss_kb[kWarmupFrames / kSampleEvery];
  const long highest_after =
      *std::max_element(rss_kb.begin() + kWarmupFrames / kSampleEvery, rss_kb.end());
  std::printf("VmRSS MB every %d frames: %s\n", kSampleEvery, series.c_str());
  std::printf(
      "VmRSS at frame %d: %.1f MB, highest after it: %.1f MB (+%.2f MB), at the end: "
      "%.1f MB (+%.2f MB)\n",
      kWarmupFrames, at_warmup / 1024.0, highest_after / 1024.0,
      (highest_after - at_warmup) / 1024.0, rss_kb.back() / 1024.0,
      (rss_kb.back() - at_warmup) / 1024.0);
  EXPECT_LT(highest_after - at_warmup, kMaxGrowthKb) << "VmRSS MB: " << series;
  ::testing::Test::RecordProperty("rss_at_warmup_kb", std::to_string(at_warmup));
  ::testing::Test::RecordProperty("rss_growth_kb", std::to_string(highest_after - at_warmup));
}

}  // namespace
}  // namespace fresco
