// calib_detect_recall: tag recall (tags found / tags in view) and corner error of the
// AprilGrid detector (calib/detect.h) against OpenCV's aruco on synthetic views of a whole
// board through a strong barrel lens (tests/calib/synthetic_images.h).
//   calib_detect_recall [--views N] [--blur SIGMA_PX] [--noise GREY] [--seed S]
//                       [--single] [--no-refine] [--quarter-window] [--save DIR] [--verbose]
// --single: the apriltag library alone (the detector before retries and aruco were added).
// --quarter-window: saddles found as on boards without crossing squares
// (DetectOptions::saddles_for_crossing_squares off).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "calib/detect.h"
#include "calib/detect_aruco.h"
#include "calib/sample_views.h"

using namespace fresco::calib;

int main(int argc, char** argv) {
  int views = 40;
  unsigned seed = 11;
  bool single = false, verbose = false, no_refine = false, quarter_window = false;
  SyntheticImageOptions image_options;
  std::string save;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* next = i + 1 < argc ? argv[i + 1] : "0";
    if (a == "--views")
      views = std::atoi(next), ++i;
    else if (a == "--blur")
      image_options.blur_sigma_px = std::atof(next), ++i;
    else if (a == "--noise")
      image_options.noise_px = std::atof(next), ++i;
    else if (a == "--seed")
      seed = static_cast<unsigned>(std::atoi(next)), ++i;
    else if (a == "--save")
      save = next, ++i;
    else if (a == "--single")
      single = true;
    else if (a == "--verbose")
      verbose = true;
    else if (a == "--no-refine")
      no_refine = true;
    else if (a == "--quarter-window")
      quarter_window = true;
    else {
      std::fprintf(stderr,
                   "usage: calib_detect_recall [--views N] [--blur SIGMA_PX] "
                   "[--noise GREY] [--seed S] [--single] [--no-refine] [--quarter-window] "
                   "[--save DIR] [--verbose]\n");
      return 2;
    }
  }
  BoardSpec spec;
  if (!ParseBoardSpec("aprilgrid:6x6:0.088:0.3", "board", &spec).ok()) return 1;
  const SyntheticLens lens;
  const SyntheticImageRenderer renderer(spec, lens);
  DetectOptions options;
  if (single) options.second_look = false;
  options.refine_tag_corners = !no_refine;
  options.saddles_for_crossing_squares = !quarter_window;
  int in_view = 0, ours = 0, aruco = 0, views_ok = 0, views_aruco_ok = 0;
  double sq_error = 0, max_error = 0, aruco_sq_error = 0;
  int corners = 0, aruco_corners = 0, over_2px = 0, inconsistent = 0;
  std::vector<double> errors;
  const auto poses = WholeBoardPoses(spec, lens, views, seed);
  for (size_t v = 0; v < poses.size(); ++v) {
    image_options.seed = seed * 1000 + static_cast<unsigned>(v);
    const SyntheticImage image = renderer.Render(poses[v], image_options);
    if (!save.empty())
      cv::imwrite(save + "/view" + std::to_string(100 + v).substr(1) + ".png", image.gray);
    int tags = 0;
    for (bool b : image.tag_in_view) tags += b;
    const BoardDetection d = DetectBoard(image.gray, spec, options);
    for (const CornerObservation& c : d.corners) {
      const double e = (c.pixel - image.truth[c.id]).norm();
      sq_error += e * e;
      errors.push_back(e);
      max_error = std::max(max_error, e);
      over_2px += e > 2;
      if (verbose && e > 1.5)
        std::printf(
            "  view %zu corner %d (tag %d): error %.2f px (found %.1f %.1f, true %.1f %.1f)\n", v,
            c.id, c.id / 4, e, c.pixel.x(), c.pixel.y(), image.truth[c.id].x(),
            image.truth[c.id].y());
      ++corners;
    }
    const std::vector<TagQuad> quads = DetectTagsAruco(image.gray, spec.cols * spec.rows);
    for (const TagQuad& q : quads)
      for (int k = 0; k < 4; ++k) {
        const double e = (q.p[k] - image.truth[q.id * 4 + k]).norm();
        aruco_sq_error += e * e;
        ++aruco_corners;
      }
    in_view += tags;
    ours += d.tags;
    inconsistent += d.corners_inconsistent;
    aruco += static_cast<int>(quads.size());
    views_ok += d.found;
    views_aruco_ok += quads.size() >= 2;
    if (verbose)
      std::printf("view %2zu: %2d tags in view, ours %2d (%s), aruco %2zu\n", v, tags, d.tags,
                  d.found ? "found" : d.reason.c_str(), quads.size());
  }
  std::printf("%zu views (blur %.2f px, noise %.1f): tags in view %d\n", poses.size(),
              image_options.blur_sigma_px, image_options.noise_px, in_view);
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  std::printf(
      "%-10s recall %.3f (%d tags, %d corners), views with a board %d, corner error rms %.3f "
      "px, median %.4f px, max %.3f px, %d over 2 px (%d dropped: their neighbours place them "
      "elsewhere)\n",
      single ? "apriltag" : "fresco", ours / double(in_view), ours, corners, views_ok,
      std::sqrt(sq_error / std::max(1, corners)), errors.empty() ? 0.0 : errors[errors.size() / 2],
      max_error, over_2px, inconsistent);
  std::printf(
      "%-10s recall %.3f (%d tags), views with >= 2 tags %d, corner error rms %.3f px "
      "(unrefined)\n",
      "aruco", aruco / double(in_view), aruco, views_aruco_ok,
      std::sqrt(aruco_sq_error / std::max(1, aruco_corners)));
  return 0;
}
