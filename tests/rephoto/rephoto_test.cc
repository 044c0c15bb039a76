// pipeline/rephoto/: the one held-out scorer, and `fresco rephoto`'s leave-one-out virtual
// rephotography, on synthetic captures whose truth is known. Perfect poses rephotograph
// well; a frame given a wrong pose scores far below the others; the local 1 - NCC is 0 for images
// equal up to gain and offset; bad input is one line naming the file and field, exit 2.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pipeline/core/image_metrics.h"
#include "pipeline/core/project.h"
#include "pipeline/rephoto/holdout_scorer.h"
#include "pipeline/rephoto/rephoto_report.h"
#include "pipeline/rephoto/rephoto_run.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/run/paint_run.h"
#include "pipeline/synth/procedural_scenes.h"
#include "pipeline/synth/synth_writer.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

using testing::MakeTempDir;
using testing::ReadText;
using testing::RunFresco;
using testing::WriteText;

constexpr int kFrames = 10;

// A small cube-room capture (160 x 120, perfect poses); returns its project.json.
std::string MakeCapture(const std::string& tag) {
  Scene scene;
  EXPECT_TRUE(MakeCubeRoomScene(CubeRoomOptions(), &scene).ok());
  SynthOptions o;
  o.frames = kFrames;
  o.width = 160, o.height = 120;
  o.radius_m = 0.6, o.height_m = 1.5;
  o.seed = 5;
  const std::string dir = MakeTempDir(tag) + "/capture";
  EXPECT_TRUE(WriteSynthCapture(scene, o, dir, SynthWriteOptions()).ok());
  return dir + "/project.json";
}

// Moves the camera of frame `name` in images.txt by `dx_m` along the camera's x axis.
void ShiftPose(const std::string& images_txt, const std::string& name, double dx_m) {
  std::istringstream in(ReadText(images_txt));
  std::string out, line;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] != '#' && line.size() > name.size() &&
        line.compare(line.size() - name.size(), name.size(), name) == 0) {
      std::istringstream fields(line);
      std::vector<std::string> f;
      for (std::string x; fields >> x;) f.push_back(x);
      f[5] = std::to_string(std::stod(f[5]) + dx_m);  // TX: x_cam = R x_world + t
      line.clear();
      for (const std::string& x : f) line += (line.empty() ? "" : " ") + x;
    }
    out += line + "\n";
  }
  WriteText(images_txt, out);
}

TEST(LocalOneMinusNcc, ZeroUpToGainAndOffsetOneForNoise) {
  cv::Mat a(60, 80, CV_8UC3);
  cv::randu(a, 40, 160);
  cv::Mat b;
  a.convertTo(b, CV_8UC3, 1.5, 10);  // gain and offset: no saturation (<= 250)
  const cv::Mat mask(a.size(), CV_8U, cv::Scalar(255));
  EXPECT_NEAR(LocalOneMinusNcc(a, a, mask), 0.0, 1e-9);
  EXPECT_NEAR(LocalOneMinusNcc(a, b, mask), 0.0, 0.01);  // rounding to 8 bits
  cv::Mat c(a.size(), CV_8UC3);
  cv::randu(c, 40, 160);
  EXPECT_NEAR(LocalOneMinusNcc(a, c, mask), 1.0, 0.1);  // independent noise
  // Only pixels whose 9 x 9 box lies in the mask: a mask smaller than a box scores nothing.
  cv::Mat small(a.size(), CV_8U, cv::Scalar(0));
  small(cv::Rect(10, 10, 8, 8)).setTo(255);
  EXPECT_TRUE(std::isnan(LocalOneMinusNcc(a, c, small)));
}

// The one held-out scorer, on frames a paint run held out: the figures are means over the
// frames; a frame at its true pose scores the same there; a wrong given pose scores low at
// it and high at the true pose; nothing scored leaves the means NaN; a stop stops.
TEST(HoldoutScorer, ScoresHeldOutFramesAtTheirGivenAndTruePoses) {
  Project project;
  ASSERT_TRUE(LoadProject(MakeCapture("holdout-scorer"), {}, &project).ok());
  PaintJobOptions job_options;
  job_options.joint_holdout_every = 3;
  std::unique_ptr<PaintJob> job;
  ASSERT_TRUE(OpenPaintJob(project, job_options, &job).ok());
  PaintRunOptions run_options;
  run_options.holdout_every = 3;  // frames 1, 4, 7
  PaintRun run(job->session.get(), job->source.get(), run_options);
  std::vector<HeldOutFrame> held_out;
  PaintRunHooks hooks;
  hooks.after_frame = [&](const RunFrame& f, const FrameReport*) {
    if (f.fate == FrameFate::kHeldOut) held_out.push_back(HeldOutFrameOf(f, &job->captures[0]));
    return Status::Ok();
  };
  ASSERT_TRUE(RunToEnd(&run, hooks).ok());
  ASSERT_EQ(held_out.size(), 3u);
  for (const HeldOutFrame& h : held_out) ASSERT_TRUE(h.true_cam_from_world.has_value());

  HoldoutScorerOptions options;
  options.keep_views = true;
  HoldoutScorer empty(job->session->PaintedScene(), options);
  EXPECT_TRUE(std::isnan(empty.figures().psnr_db));
  EXPECT_TRUE(std::isnan(empty.figures().completeness));
  EXPECT_FALSE(empty.AddAll(held_out, [] { return true; }));
  EXPECT_EQ(empty.figures().frames, 0);

  HoldoutScorer scorer(job->session->PaintedScene(), options);
  double psnr_sum = 0;
  for (const HeldOutFrame& h : held_out) {
    const HeldOutScore& s = scorer.Add(h);
    ASSERT_TRUE(s.truth.has_value());
    EXPECT_EQ(s.truth->psnr_db, s.rephoto.psnr_db);  // the true pose is the given one
    EXPECT_EQ(s.view.rendered_bgr.size(), h.photo_bgr.size());
    psnr_sum += s.rephoto.psnr_db;
  }
  const HoldoutFigures& f = scorer.figures();
  EXPECT_EQ(f.frames, 3);
  EXPECT_EQ(f.scored, 3);
  EXPECT_EQ(f.truth_scored, 3);
  EXPECT_DOUBLE_EQ(f.psnr_db, psnr_sum / 3);
  EXPECT_GT(f.psnr_db, 30.0);
  EXPECT_GT(f.completeness, 0.95);
  EXPECT_LT(f.local_one_minus_ncc, 0.15);
  EXPECT_EQ(f.MoverLeak(), 0.0);  // no SceneTruth: no mover figures

  // A given pose 15 cm off: low at it, as high as before at the true pose.
  HeldOutFrame wrong = held_out[1];
  wrong.cam_from_world.translation.x() += 0.15;
  const HeldOutScore& w = scorer.Add(wrong);
  std::printf("held out at a wrong pose: %.2f dB there, %.2f dB at the true pose\n",
              w.rephoto.psnr_db, w.truth->psnr_db);
  EXPECT_LT(w.rephoto.psnr_db, w.truth->psnr_db - 12.0);
  EXPECT_GT(w.truth->psnr_db, 30.0);
}

TEST(Rephoto, PerfectPosesScoreHighAndAWrongPoseScoresLow) {
  const std::string project = MakeCapture("rephoto-good");
  RephotoOptions options;
  RephotoResult good;
  int views = 0;
  const RephotoViewSink count = [&](const RephotoFrame&, const cv::Mat& r, const cv::Mat& p) {
    EXPECT_EQ(r.size(), p.size());
    ++views;
    return Status::Ok();
  };
  ASSERT_TRUE(RunRephoto(project, options, count, &good).ok());
  ASSERT_EQ(good.frames.size(), static_cast<size_t>(kFrames));
  EXPECT_EQ(views, kFrames);
  const RephotoSummary s = SummarizeRephoto(good);
  for (const RephotoFrame& f : good.frames) EXPECT_EQ(f.frames_painted, kFrames - 1) << f.name;
  EXPECT_GT(s.psnr_db.median, 30.0);
  EXPECT_LT(s.one_minus_ncc.median, 0.15);
  EXPECT_GT(s.completeness.median, 0.95);

  // Frame 000004.png's given pose 15 cm off (the room is 4 m; about 9 px at its distance).
  const std::string dir = std::filesystem::path(project).parent_path().string();
  ShiftPose(dir + "/sparse/images.txt", "000004.png", 0.15);
  RephotoResult bad;
  ASSERT_TRUE(RunRephoto(project, options, nullptr, &bad).ok());
  ASSERT_EQ(bad.frames.size(), static_cast<size_t>(kFrames));
  const RephotoFrame& wrong = bad.frames[4];
  EXPECT_EQ(wrong.name, "000004.png");
  std::printf(
      "perfect poses: PSNR median %.2f worst %.2f dB, 1-NCC median %.3f; frame 4 at "
      "a wrong pose: %.2f dB (%.2f at its true pose), 1-NCC %.3f\n",
      s.psnr_db.median, s.psnr_db.worst, s.one_minus_ncc.median, wrong.psnr_db,
      good.frames[4].psnr_db, wrong.one_minus_ncc);
  EXPECT_LT(wrong.psnr_db, good.frames[4].psnr_db - 12.0);
  EXPECT_GT(wrong.one_minus_ncc, 0.7);
  // It is the worst, by far.
  EXPECT_EQ(SummarizeRephoto(bad).psnr_db.worst, wrong.psnr_db);

  // --every 3: frames 0, 3, 6, 9 left out.
  options.every = 3;
  RephotoResult every;
  ASSERT_TRUE(RunRephoto(project, options, nullptr, &every).ok());
  ASSERT_EQ(every.frames.size(), 4u);
  EXPECT_EQ(every.frames[1].name, "000003.png");
}

TEST(Rephoto, CommandWritesTablesAndViewsAndRefusesBadInput) {
  const std::string project = MakeCapture("rephoto-cli");
  const std::string out = MakeTempDir("rephoto-out") + "/out";
  testing::CommandResult r = RunFresco({"rephoto", project, "--out", out, "--every", "5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json doc = nlohmann::json::parse(ReadText(out + "/rephoto.json"));
  ASSERT_EQ(doc["frames"].size(), 2u);
  EXPECT_GT(doc["summary"]["psnr_db"]["median"].get<double>(), 26.0);
  EXPECT_NE(ReadText(out + "/rephoto.md").find("| **median** |"), std::string::npos);
  const cv::Mat view = cv::imread(out + "/views/000005.png");
  EXPECT_EQ(view.cols, 2 * 160);

  // A project whose poses file holds one pose: exit 2, one line naming it.
  const std::string dir = std::filesystem::path(project).parent_path().string();
  std::istringstream in(ReadText(dir + "/sparse/images.txt"));
  std::string kept, line;
  int poses = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (poses++ < 1) kept += line + "\n\n";
    std::getline(in, line);  // its points line
  }
  WriteText(dir + "/sparse/images.txt", kept);
  r = RunFresco({"rephoto", project, "--out", out + "2"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("images.txt: poses: rephotography needs at least 2 frames"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  // An unknown setting names its JSON path; --every 0 is a usage error.
  r = RunFresco({"rephoto", project, "--out", out + "3", "--set", "pipeline.nonsense=1"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("pipeline.nonsense"), std::string::npos) << r.err;
  r = RunFresco({"rephoto", project, "--out", out + "4", "--every", "0"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--every"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace fresco
