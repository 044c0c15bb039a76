// AprilGrid detection on synthetic views of Kalibr's printed board (black squares where the
// gaps cross) through a strong barrel lens, sharp and blurred: tag recall (tags found / tags
// in view) against a bound the apriltag library alone misses, and corner error against the
// true projection. Figures for a larger set: `build/tests/calib_detect_recall`.
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <gtest/gtest.h>

#include "calib/detect.h"
#include "calib/detect_aruco.h"
#include "calib/sample_views.h"
#include "calib/tags_around_found.h"
#include "tests/calib/synthetic_boards.h"

namespace fresco::calib::testing {
namespace {

struct RecallFigures {
  int in_view = 0, found = 0, views_found = 0, corners = 0;
  double corner_rms_px = 0;
  double median_corner_px = 0;
  double max_corner_px = 0;
  int corners_over_2px = 0;
  int views_with_squares = 0;  // BoardDetection::crossing_squares
};

RecallFigures Measure(const std::vector<SyntheticImage>& images, const BoardSpec& spec,
                      const DetectOptions& options) {
  RecallFigures f;
  double sq = 0;
  std::vector<double> errors;
  for (const SyntheticImage& image : images) {
    for (bool in : image.tag_in_view) f.in_view += in;
    const BoardDetection d = DetectBoard(image.gray, spec, options);
    f.found += d.tags;
    f.views_found += d.found;
    f.views_with_squares += d.crossing_squares;
    for (const CornerObservation& c : d.corners) {
      const double e = (c.pixel - image.truth[c.id]).norm();
      sq += e * e;
      errors.push_back(e);
      f.max_corner_px = std::max(f.max_corner_px, e);
      f.corners_over_2px += e > 2;
    }
  }
  f.corners = static_cast<int>(errors.size());
  f.corner_rms_px = std::sqrt(sq / std::max<size_t>(1, errors.size()));
  if (!errors.empty()) {
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
    f.median_corner_px = errors[errors.size() / 2];
  }
  return f;
}

RecallFigures Measure(const std::vector<SyntheticImage>& images, const BoardSpec& spec,
                      bool second_look) {
  DetectOptions options;
  options.second_look = second_look;
  return Measure(images, spec, options);
}

std::vector<SyntheticImage> Views(double blur_sigma_px, int count, double noise = 1) {
  const BoardSpec spec = Spec("aprilgrid:6x6:0.088:0.3");
  const SyntheticLens lens;
  const SyntheticImageRenderer renderer(spec, lens);
  std::vector<SyntheticImage> images;
  SyntheticImageOptions options;
  options.blur_sigma_px = blur_sigma_px;
  options.noise_px = noise;
  for (const auto& pose : WholeBoardPoses(spec, lens, count, 11)) {
    ++options.seed;
    images.push_back(renderer.Render(pose, options));
  }
  return images;
}

// Measured on these 12 views (seed 11), apriltag alone / with the second look (retries, aruco,
// then around the tags found): sharp: recall 0.347 / 0.917, 12 / 12 boards; blur 1 px: recall
// 0.079 / 0.641, 4 / 10 boards; median corner error 0.08 and 0.04 px, rms 0.131 and 0.065 px.
// (Before the look around found tags: recall 0.731 and 0.595; before corners that do not
// settle on a saddle were left out: rms 0.349 and 0.126 px.)
TEST(AprilGridRecallTest, SecondLookKeepsBoardsUnderStrongBarrelDistortion) {
  const BoardSpec spec = Spec("aprilgrid:6x6:0.088:0.3");
  for (double blur : {0.0, 1.0}) {
    const std::vector<SyntheticImage> images = Views(blur, 12);
    ASSERT_EQ(images.size(), 12u);
    const RecallFigures before = Measure(images, spec, false);
    const RecallFigures after = Measure(images, spec, true);
    const double recall_before = before.found / double(before.in_view);
    const double recall_after = after.found / double(after.in_view);
    std::printf(
        "blur %.1f px: recall %.3f -> %.3f, boards %d -> %d of %zu, corner rms %.3f -> "
        "%.3f px (median %.3f px)\n",
        blur, recall_before, recall_after, before.views_found, after.views_found, images.size(),
        before.corner_rms_px, after.corner_rms_px, after.median_corner_px);
    EXPECT_LT(recall_before, 0.4) << blur;  // the bound below is out of the old code's reach
    EXPECT_GE(recall_after, blur > 0 ? 0.62 : 0.85) << blur;
    EXPECT_GE(after.views_found, 10) << blur;
    EXPECT_LT(after.median_corner_px, 0.3) << blur;
    EXPECT_LT(after.corner_rms_px, 0.2) << blur;
  }
}

// Corners that cornerSubPix settled on a tag's edge instead of its corner (foreshortened tags
// under the strong barrel lens) are dropped where the board's corners near them place them
// elsewhere. Measured on these 40 views: kept without the check 4,764 corners, rms 0.232 px,
// 8 more than 2 px off, the worst 5.85 px; with it 4,732, 0.141 px, none, 1.92 px.
// `calib_detect_recall --seed 101 / 202 / 303` (not looked at while choosing the limits): more than
// 2 px off 6 / 0 / 5 -> 0 / 0 / 2, the worst 4.47 / 1.69 / 4.49 -> 1.91 / 1.69 / 3.80 px.
TEST(AprilGridRecallTest, CornersOnATagsEdgeAreDroppedWhereTheirNeighboursPlaceThemElsewhere) {
  const BoardSpec spec = Spec("aprilgrid:6x6:0.088:0.3");
  const std::vector<SyntheticImage> images = Views(0.0, 40);
  DetectOptions without;
  without.drop_inconsistent_corners = false;
  without.edges_from_outline_when_strayed = false;  // it removes most of them too: below
  const RecallFigures before = Measure(images, spec, without);
  const RecallFigures after = Measure(images, spec, DetectOptions());
  // Since 2026-12-06 a saddle more than 1 px from the outline with no square at it has its
  // edges looked for from the outline (or is left out): without the check, 0 corners over
  // 2 px, the worst 1.69 px, rms 0.135 px.
  without.edges_from_outline_when_strayed = true;
  const RecallFigures outline_only = Measure(images, spec, without);
  EXPECT_LE(outline_only.corners_over_2px, 1);
  EXPECT_LT(outline_only.max_corner_px, 2.6);
  EXPECT_LT(outline_only.corner_rms_px, 0.8 * before.corner_rms_px);
  std::printf("corners %d -> %d, rms %.3f -> %.3f px, over 2 px %d -> %d, worst %.2f -> %.2f px\n",
              before.corners, after.corners, before.corner_rms_px, after.corner_rms_px,
              before.corners_over_2px, after.corners_over_2px, before.max_corner_px,
              after.max_corner_px);
  EXPECT_GE(before.corners_over_2px, 5);  // what the check is for
  EXPECT_GT(before.max_corner_px, 4.0);
  EXPECT_LE(after.corners_over_2px, 1);
  EXPECT_LT(after.max_corner_px, 2.6);
  EXPECT_LT(after.corner_rms_px, 0.8 * before.corner_rms_px);
  EXPECT_GT(after.corners, 0.98 * before.corners);  // few right corners lost
  EXPECT_EQ(after.found, before.found);             // no tag lost
}

// On Kalibr's board every tag corner is a saddle with the square beside it: cornerSubPix's
// window is widened to a seventh of the tag's edge (short of the square's middle, where the
// next saddle's pull starts) against the quarter used where no square is, so a blurred, noisy
// saddle is found from more of its slopes (a corner where the two windows disagree by more
// than 0.5 px left out). These 12 views, blurred 1 px, grey noise 3 (the photos' JPEG and
// sensor noise): median 0.0529 -> 0.0497 px, rms 0.0757 -> 0.0715 px from the truth. The
// real photos gain most (yac's, tests/calib/calib_test.cc): median distance from yac's
// corners 0.096 -> 0.088 px.
TEST(AprilGridRecallTest, SaddlesBesideCrossingSquaresAreFoundWithTheWindowTheSquareLeaves) {
  const BoardSpec spec = Spec("aprilgrid:6x6:0.088:0.3");
  const std::vector<SyntheticImage> images = Views(1.0, 12, 3.0);
  DetectOptions quarter;
  quarter.saddles_for_crossing_squares = false;
  const RecallFigures before = Measure(images, spec, quarter);
  const RecallFigures after = Measure(images, spec, DetectOptions());
  std::printf(
      "blurred: corners %d -> %d, rms %.4f -> %.4f px, median %.4f -> %.4f px, worst %.2f "
      "-> %.2f px\n",
      before.corners, after.corners, before.corner_rms_px, after.corner_rms_px,
      before.median_corner_px, after.median_corner_px, before.max_corner_px, after.max_corner_px);
  EXPECT_EQ(before.views_with_squares, 0);
  EXPECT_GE(after.views_with_squares, after.views_found);
  EXPECT_EQ(after.found, before.found);  // the same tags
  EXPECT_LT(after.corner_rms_px, before.corner_rms_px);
  EXPECT_LT(after.median_corner_px, 0.97 * before.median_corner_px);
}

// The look around found tags: tags the detector found, taken out of what it found, are
// found again from their neighbours, where they are.
TEST(AprilGridRecallTest, TagsTakenOutComeBackFromTheirNeighboursWhereTheyAre) {
  const BoardSpec spec = Spec("aprilgrid:6x6:0.088:0.3");
  const int num_ids = spec.cols * spec.rows;
  int taken = 0, back = 0;
  double worst_px = 0, library_worst_px = 0, sq = 0, library_sq = 0;
  int library_corners = 0;
  for (const SyntheticImage& image : Views(0, 6)) {
    std::map<int, TagQuad> found;
    for (const TagQuad& q : DetectTagsApriltag(image.gray, num_ids)) {
      found.emplace(q.id, q);
      for (int k = 0; k < 4; ++k) {
        const double e = (q.p[k] - image.truth[4 * q.id + k]).norm();
        library_worst_px = std::max(library_worst_px, e);
        library_sq += e * e;
        ++library_corners;
      }
    }
    // Every third tag found, kept out.
    std::vector<int> out;
    int i = 0;
    for (auto it = found.begin(); it != found.end();)
      if (i++ % 3 == 1) {
        out.push_back(it->first);
        it = found.erase(it);
      } else {
        ++it;
      }
    const std::set<int> before = [&] {
      std::set<int> ids;
      for (const auto& [id, q] : found) ids.insert(id);
      return ids;
    }();
    FindTagsAroundFound(
        image.gray, spec, [&](const cv::Mat& patch) { return DetectTagsApriltag(patch, num_ids); },
        &found);
    taken += static_cast<int>(out.size());
    for (const auto& [id, q] : found) {
      if (before.count(id)) continue;
      ASSERT_TRUE(image.tag_in_view[id]) << "tag " << id << " is not in the view";
      if (std::find(out.begin(), out.end(), id) != out.end()) ++back;
      for (int k = 0; k < 4; ++k) {
        const double e = (q.p[k] - image.truth[4 * id + k]).norm();
        worst_px = std::max(worst_px, e);
        sq += e * e;
      }
    }
  }
  const double rms_px = std::sqrt(sq / std::max(1, 4 * back));
  const double library_rms_px = std::sqrt(library_sq / std::max(1, library_corners));
  std::printf(
      "%d of %d tags taken out found again, corners rms %.2f px, worst %.2f px (the library's "
      "own, unrefined: %.2f / %.2f px)\n",
      back, taken, rms_px, worst_px, library_rms_px, library_worst_px);
  ASSERT_GT(taken, 20);
  EXPECT_GE(back, 0.9 * taken);
  EXPECT_LT(rms_px, 1.5 * library_rms_px);
  EXPECT_LT(worst_px, 3.0);
}

// aruco's corners, re-ordered into the apriltag library's order, land on the true corners
// (a wrong order would put them a tag edge away).
TEST(AprilGridRecallTest, ArucoCornersFollowTheApriltagOrder) {
  const BoardSpec spec = Spec("aprilgrid:6x6:0.088:0.3");
  const std::vector<SyntheticImage> images = Views(0, 3);
  int quads = 0;
  for (const SyntheticImage& image : images)
    for (const TagQuad& q : DetectTagsAruco(image.gray, spec.cols * spec.rows)) {
      ++quads;
      for (int k = 0; k < 4; ++k) EXPECT_LT((q.p[k] - image.truth[q.id * 4 + k]).norm(), 8) << k;
    }
  EXPECT_GT(quads, 20);
}

}  // namespace
}  // namespace fresco::calib::testing
