// Seam levelling (seam_levelling.h): a frame whose light falls off across it is brought back
// to what the buffers hold where they overlap, the correction fades into what they have not
// painted, and a vignetted capture paints with fewer seams (local 1 - NCC against the truth).
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_metrics.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/seam_levelling.h"
#include "pipeline/render/renderer.h"
#include "tests/paint/rephotograph.h"
#include "tests/paint/room_capture.h"
#include "tests/paint/synth_session.h"

namespace fresco {
namespace {

// A buffer rectangle of w x h texels: its left half keeps a painted texture, the frame sees
// all of it with the light falling off from left to right (gain 1.0 -> 0.6) and paints the
// right half (the left half's samples are marked kept, as the select stage leaves them).
struct RampCase {
  static constexpr int kW = 256, kH = 64;
  PaintedBuffer painted;
  WarpedBuffer warped;
  cv::Mat kept;
  cv::Mat truth;  // CV_8UC3

  RampCase() {
    truth.create(kH, kW, CV_8UC3);
    cv::RNG rng(5);
    rng.fill(truth, cv::RNG::UNIFORM, cv::Scalar(60, 70, 80), cv::Scalar(200, 190, 180));
    cv::GaussianBlur(truth, truth, cv::Size(5, 5), 1.0);
    painted.bgra = cv::Mat(kH, kW, CV_8UC4, cv::Scalar(255, 255, 255, 0));
    painted.quality = cv::Mat(kH, kW, CV_32F, cv::Scalar(0));
    kept = cv::Mat::zeros(kH, kW, CV_8U);
    warped.valid = cv::Mat::zeros(kH, kW, CV_8U);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        if (x < kW / 2) {
          const cv::Vec3b t = truth.at<cv::Vec3b>(y, x);
          painted.bgra.at<cv::Vec4b>(y, x) = cv::Vec4b(t[0], t[1], t[2], 255);
          painted.quality.at<float>(y, x) = 1.0f;
          kept.at<uint8_t>(y, x) = 255;
        } else {
          warped.valid.at<uint8_t>(y, x) = 255;
        }
      }
    warped.bgr.create(kH, kW, CV_8UC3);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const double gain = 1.0 - 0.4 * x / (kW - 1);
        const cv::Vec3b t = truth.at<cv::Vec3b>(y, x);
        for (int c = 0; c < 3; ++c)
          warped.bgr.at<cv::Vec3b>(y, x)[c] = cv::saturate_cast<uint8_t>(t[c] * gain);
      }
    warped.quality = cv::Mat(kH, kW, CV_32F, cv::Scalar(1));
    warped.valid_box = cv::Rect(0, 0, kW, kH);
  }

  // Mean |sample - truth| over columns [x0, x1), grey levels.
  double MeanError(int x0, int x1) const {
    double sum = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = x0; x < x1; ++x)
        for (int c = 0; c < 3; ++c)
          sum += std::abs(warped.bgr.at<cv::Vec3b>(y, x)[c] - truth.at<cv::Vec3b>(y, x)[c]);
    return sum / (3.0 * kH * (x1 - x0));
  }
};

TEST(SeamLevelling, NewSamplesContinueTheKeptColoursAtTheSeamAndKeepTheirOwnBeyond) {
  RampCase ramp;
  const RampCase original;
  constexpr int kSeam = RampCase::kW / 2;
  const double before_seam = ramp.MeanError(kSeam, kSeam + 8);
  SeamLevelOptions options;
  options.cell_texels = 16;
  const SeamLevelStats stats = LevelSeams(ramp.painted, ramp.kept, options, &ramp.warped);
  const double after_seam = ramp.MeanError(kSeam, kSeam + 8);
  std::printf("mean error beside the seam %.2f -> %.2f levels; %d cells measured, %d filled\n",
              before_seam, after_seam, stats.cells_measured, stats.cells_filled);
  EXPECT_EQ(stats.cells_measured, 8 * 4);  // the kept half: 8 x 4 cells of 16
  EXPECT_EQ(stats.cells_filled, 4 * 4);    // four cells on into the painted half
  EXPECT_GT(before_seam, 20.0);
  EXPECT_LT(after_seam, 0.5 * before_seam);  // the step at the seam mostly gone
  // The kept texels' samples are not touched (they are not painted) ...
  const cv::Rect left(0, 0, kSeam, RampCase::kH);
  EXPECT_EQ(cv::norm(ramp.warped.bgr(left), original.warped.bgr(left), cv::NORM_INF), 0.0);
  // ... and beyond the correction's reach the frame keeps its own colours.
  const cv::Rect far(RampCase::kW - 40, 0, 40, RampCase::kH);
  EXPECT_EQ(cv::norm(ramp.warped.bgr(far), original.warped.bgr(far), cv::NORM_INF), 0.0);
}

TEST(SeamLevelling, NothingKeptNothingChanged) {
  RampCase ramp;
  const cv::Mat before = ramp.warped.bgr.clone();
  EXPECT_EQ(LevelSeams(ramp.painted, cv::Mat(), SeamLevelOptions(), &ramp.warped).cells_measured,
            0);
  ramp.kept.setTo(0);
  EXPECT_EQ(LevelSeams(ramp.painted, ramp.kept, SeamLevelOptions(), &ramp.warped).cells_measured,
            0);
  EXPECT_EQ(cv::norm(ramp.warped.bgr, before, cv::NORM_INF), 0.0);
}

// The room's hand-held capture with every frame vignetted (gain 1 at the centre, 0.55 in the
// corners): the views selection keeps leave their falloff in the texture, which shows as
// seams where one view's region meets the next. Levelled, fewer seams: local 1 - NCC against
// the true room at four of the frames' poses.
TEST(SeamLevelling, VignettedFramesPaintWithFewerSeams) {
  const Scene scene = testing::RoomScene();
  SynthOptions o = testing::HandheldRoomCapture(24, 0.8);
  o.seed = 3;
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &capture).ok());
  const cv::Size size = capture.frames_bgr[0].size();
  cv::Mat falloff(size, CV_32FC3);
  const double half_diagonal = 0.5 * std::hypot(size.width, size.height);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const double r = std::hypot(x - 0.5 * size.width, y - 0.5 * size.height) / half_diagonal;
      const float g = static_cast<float>(1.0 - 0.45 * r * r);
      falloff.at<cv::Vec3f>(y, x) = cv::Vec3f(g, g, g);
    }
  for (cv::Mat& frame : capture.frames_bgr) {
    cv::Mat f;
    frame.convertTo(f, CV_32FC3);
    cv::multiply(f, falloff, f);
    f.convertTo(frame, CV_8UC3);
  }

  const auto ncc = [&](const PipelineOptions& options, double* psnr) {
    const Scene painted = testing::PaintAllFrames(scene, capture, options);
    const Renderer renderer(capture.camera, RenderOptions());
    double sum = 0;
    *psnr = 0;
    const std::vector<int> views = {3, 9, 15, 21};
    for (int i : views) {
      const testing::TruthAndPainted r = testing::RenderTruthAndPainted(
          renderer, scene, painted, capture.true_poses[i].cam_from_world);
      sum += LocalOneMinusNcc(r.truth_bgr, r.painted_bgr, r.both) / views.size();
      *psnr += PsnrDb(r.truth_bgr, r.painted_bgr, r.both) / views.size();
    }
    return sum;
  };
  PipelineOptions off;
  off.background.mode = BackgroundMode::kOff;
  off.refine.mode = RefineMode::kOff;
  off.select.enabled = true;
  // Exposure matching off: one gain and offset per frame cannot undo a falloff across the
  // frame (its fit drifts towards a washed-out texture here, 16 dB); levelling alone is tested.
  off.select.exposure = false;
  PipelineOptions on = off;
  on.select.level_seams = true;
  double psnr_off = 0, psnr_on = 0;
  const double ncc_off = ncc(off, &psnr_off);
  const double ncc_on = ncc(on, &psnr_on);
  std::printf("vignetted room: 1 - NCC %.4f -> %.4f levelled; PSNR %.2f -> %.2f dB\n", ncc_off,
              ncc_on, psnr_off, psnr_on);
  EXPECT_LT(ncc_on, ncc_off - 0.015);
  // The kept colours are carried into the new samples only as far as the fade: the texture
  // keeps its level (a correction chained frame after frame darkened it by 4 dB).
  EXPECT_GT(psnr_on, psnr_off - 1.2);
}

}  // namespace
}  // namespace fresco
