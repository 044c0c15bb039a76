// calib_detect_elsewhere: the AprilGrid detector (calib/detect.h) on boards drawn and
// photographed by OpenCV alone (tests/calib/opencv_boards.h), issue 56's held-out set: per
// variant (seed x dark/light surround x sharp / blurred 1 px + JPEG 80), the views the
// detector loses where OpenCV's aruco (default parameters) reads 4 or more of the board's
// tags, tags read by each, and detection time; --solve also solves the views (opencv4) and
// prints the lens's RMS distance from the truth over the imager (5-95 %, 40 x 30 points) and
// where the boards were seen (those of the points inside the convex hull of every corner
// the solve used).
//   calib_detect_elsewhere [--views N] [--seeds S1,S2,..] [--border-bits 1|2]
//                          [--margin TAGS] [--gamma G] [--contrast C] [--vignette V]
//                          [--solve] [--save DIR] [--verbose] [--no-second-look]
//                          [--only dark_sharp|dark_blur|light_sharp|light_blur] [--per-view]
//                          [--truth-corners] [--truth-at found|outline|inner]
//                          [--truth-above PX] [--truth-noise PX] [--corners-from FILE]
//                          [--dump FILE] [--halfway] [--solve-lock FILE]
// --verbose also lists every corner more than 2 px from the truth; the corners' errors are
// also given apart for those on the board's outline (an outer tag's outer edge through them);
// --per-view gives them for each view, with its tag edge shift. To tell which corners bias the
// lens, the solve can take the true pixel instead of the one found: of every corner of the
// board (--truth-corners: the solve's floor), of the corners found (--truth-at found: what the
// corners left out cost), of those on the outline or the others found, of those more than PX
// off (--truth-above); --dump writes every corner found, one a line: variant, view, id, on the
// outline (1) or not, x, y, then the true pixels of its tag's corners from it on (k, k + 1, ..).
#include <sys/file.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/calibrate.h"
#include "calib/detect.h"
#include "calib/lens_projection.h"
#include "tests/calib/opencv_boards.h"

using namespace fresco::calib;
using namespace fresco::calib::testing;

int main(int argc, char** argv) {
  int views = 40;
  std::vector<unsigned> seeds = {1, 2, 3};
  ElsewhereBoard board;
  bool solve = false, verbose = false, truth_corners = false, per_view = false;
  std::string save, only, truth_at, dump, corners_from, solve_lock;
  double truth_above_px = 1e9, truth_noise_px = 0;
  DetectOptions options;
  ElsewhereShot look;  // the tone curve and vignetting every view gets
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const char* next = i + 1 < argc ? argv[i + 1] : "0";
    if (a == "--views") {
      views = std::atoi(next), ++i;
    } else if (a == "--seeds") {
      seeds.clear();
      std::stringstream list(next);
      for (std::string s; std::getline(list, s, ',');) seeds.push_back(std::atoi(s.c_str()));
      ++i;
    } else if (a == "--border-bits") {
      board.border_bits = std::atoi(next), ++i;
    } else if (a == "--margin") {
      board.margin_tags = std::atof(next), ++i;
    } else if (a == "--gamma") {
      look.gamma = std::atof(next), ++i;
    } else if (a == "--contrast") {
      look.contrast = std::atof(next), ++i;
    } else if (a == "--vignette") {
      look.vignette = std::atof(next), ++i;
    } else if (a == "--save") {
      save = next, ++i;
    } else if (a == "--solve") {
      solve = true;
    } else if (a == "--truth-corners") {  // solve from the true corners (the solve's floor)
      truth_corners = true;
    } else if (a == "--truth-at") {  // the true pixel of the corners found: found|outline|inner
      truth_at = next, ++i;
    } else if (a == "--truth-above") {  // the true pixel of the corners found more than PX off
      truth_above_px = std::atof(next), ++i;
    } else if (a == "--truth-noise") {  // --truth-at's true pixels plus Gaussian noise (px)
      truth_noise_px = std::atof(next), ++i;
    } else if (a == "--corners-from") {  // the pixels the solve takes: variant view id x y lines
      corners_from = next, ++i;
    } else if (a == "--dump") {  // every corner found: variant view id outline x y, the truth
      dump = next, ++i;
    } else if (a == "--only") {  // one variant: dark_sharp, dark_blur, light_sharp, light_blur
      only = next, ++i;
    } else if (a == "--per-view") {  // each view's edge shift and corner errors
      per_view = true;
    } else if (a == "--verbose") {
      verbose = true;
    } else if (a == "--halfway") {  // edges halfway, one shift undone (before the edge level)
      options.edge_level_from_pitch = false;
    } else if (a == "--solve-lock") {  // one solve at a time among processes sharing FILE
      solve_lock = next, ++i;
    } else if (a == "--no-second-look") {
      options.second_look = false;
    } else {
      std::fprintf(
          stderr,
          "usage: calib_detect_elsewhere [--views N] [--seeds S1,S2] [--border-bits 1|2] "
          "[--margin TAGS] [--gamma G] [--contrast C] [--vignette V] [--solve] "
          "[--save DIR] [--verbose] [--no-second-look] [--only dark_blur|...] [--per-view] "
          "[--truth-corners] [--truth-at found|outline|inner] [--truth-above PX] [--truth-noise "
          "PX] "
          "[--corners-from FILE] [--dump FILE] [--halfway] [--solve-lock FILE]\n");
      return 2;
    }
  }
  BoardSpec spec;
  if (!ParseBoardSpec("aprilgrid:6x6:0.088:0.3", "board", &spec).ok()) return 1;
  const int num_ids = spec.cols * spec.rows;
  const ElsewhereLens lens;
  const ElsewhereRenderer renderer(board, lens);
  std::vector<Eigen::Vector2d> grid;
  for (int j = 0; j < 30; ++j)
    for (int i = 0; i < 40; ++i)
      grid.emplace_back(lens.width * (0.05 + 0.9 * i / 39.0),
                        lens.height * (0.05 + 0.9 * j / 29.0));
  int all_lost = 0;
  cv::RNG rng(7);
  std::map<std::string, Eigen::Vector2d> given;  // --corners-from, by "variant view id"
  if (!corners_from.empty()) {
    std::ifstream in(corners_from);
    std::string variant_name;
    size_t view_index;
    int id;
    double x, y;
    while (in >> variant_name >> view_index >> id >> x >> y)
      given[variant_name + " " + std::to_string(view_index) + " " + std::to_string(id)] = {x, y};
  }
  FILE* dump_file = dump.empty() ? nullptr : std::fopen(dump.c_str(), "w");
  for (unsigned seed : seeds) {
    const auto poses = renderer.Poses(views, seed);
    for (int surround : {20, 225})
      for (bool degraded : {false, true}) {
        if (!only.empty() && only != std::string(surround < 128 ? "dark_" : "light_") +
                                         (degraded ? "blur" : "sharp"))
          continue;
        int used = 0, lost = 0, aruco_ok = 0, tags_ours = 0, tags_aruco = 0;
        // Views whose border was read other than drawn, and whose tags came mostly from the
        // second look (the border is the most of the tags').
        int border_misread = 0, mostly_second_look = 0;
        // Corners on the board's outline (an outer tag's outer edge through them) and the
        // others: squared error, count, mean out of the tag.
        double outline_sq = 0, outline_out = 0, inner_sq = 0, inner_out = 0;
        int outline_n = 0, inner_n = 0;
        double ms = 0, ms_max = 0, sq_px = 0, worst_px = 0;
        int corners = 0;
        Eigen::Vector2d sum_px = Eigen::Vector2d::Zero();
        double sum_radial_px = 0, sum_outward_px = 0;
        std::vector<BoardView> used_views;
        const std::string variant = "s" + std::to_string(seed) +
                                    (surround < 128 ? "_dark" : "_light") +
                                    (degraded ? "_blur" : "_sharp");
        const std::string name = "seed " + std::to_string(seed) +
                                 (surround < 128 ? " dark " : " light") +
                                 (degraded ? " blur1+jpeg80" : " sharp       ");
        std::string dir;
        if (!save.empty()) {
          dir = save + "/" + variant;
          std::filesystem::create_directories(dir);
        }
        for (size_t v = 0; v < poses.size(); ++v) {
          ElsewhereShot shot = look;
          shot.surround = surround;
          shot.seed = seed * 1000 + static_cast<unsigned>(v);
          if (degraded) shot.blur_sigma_px = 1, shot.jpeg_quality = 80;
          const ElsewhereView view = renderer.Render(poses[v], shot);
          if (!dir.empty())
            cv::imwrite(dir + "/view" + std::to_string(100 + v).substr(1) + ".png", view.gray);
          const auto start = std::chrono::steady_clock::now();
          const BoardDetection d = DetectBoard(view.gray, spec, options);
          const double t_ms =
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                  .count();
          ms += t_ms, ms_max = std::max(ms_max, t_ms);
          const std::vector<int> aruco = ArucoIdsDefault(view.gray, num_ids, board.border_bits);
          const bool aruco_reads = aruco.size() >= 4;
          aruco_ok += aruco_reads;
          used += d.found;
          tags_ours += d.tags;
          tags_aruco += static_cast<int>(aruco.size());
          if (!d.found && aruco_reads) ++lost;
          border_misread += d.tags > 0 && d.border_bits != board.border_bits;
          mostly_second_look += 2 * d.tags_second_look >= d.tags && d.tags > 0;
          std::vector<CornerObservation> solved_corners;  // d.corners, or the truth (--truth-at)
          double view_out[2] = {0, 0}, view_sq[2] = {0, 0};
          int view_n[2] = {0, 0};
          for (const CornerObservation& c : d.corners) {
            const double e = (c.pixel - view.truth[c.id]).norm();
            if (verbose && e > 2)
              std::printf("  %s view %2zu: corner %d (tag %d, k %d) %.2f px off\n", name.c_str(), v,
                          c.id, c.id / 4, c.id % 4, e);
            sq_px += e * e, worst_px = std::max(worst_px, e), ++corners;
            sum_px += c.pixel - view.truth[c.id];
            const Eigen::Vector2d out = view.truth[c.id] - Eigen::Vector2d(511.5, 383.5);
            sum_radial_px += (c.pixel - view.truth[c.id]).dot(out.normalized());
            const int t0 = c.id / 4 * 4;
            const Eigen::Vector2d tag_centre = 0.25 * (view.truth[t0] + view.truth[t0 + 1] +
                                                       view.truth[t0 + 2] + view.truth[t0 + 3]);
            const double out_of_tag =
                (c.pixel - view.truth[c.id]).dot((view.truth[c.id] - tag_centre).normalized());
            sum_outward_px += out_of_tag;
            const int tag = c.id / 4, k = c.id % 4, tr = tag / spec.cols, tc = tag % spec.cols;
            const bool outline = (tr == 0 && k < 2) || (tr == spec.rows - 1 && k >= 2) ||
                                 (tc == 0 && (k == 0 || k == 3)) ||
                                 (tc == spec.cols - 1 && (k == 1 || k == 2));
            (outline ? outline_sq : inner_sq) += e * e;
            (outline ? outline_out : inner_out) += out_of_tag;
            ++(outline ? outline_n : inner_n);
            view_out[outline] += out_of_tag, view_sq[outline] += e * e, ++view_n[outline];
            if (dump_file != nullptr) {
              std::fprintf(dump_file, "%s %zu %d %d %.4f %.4f", variant.c_str(), v, c.id,
                           outline ? 1 : 0, c.pixel.x(), c.pixel.y());
              for (int j = 0; j < 4; ++j)  // the truth of the tag's corners, from this one on
                std::fprintf(dump_file, " %.4f %.4f", view.truth[t0 + (k + j) % 4].x(),
                             view.truth[t0 + (k + j) % 4].y());
              std::fprintf(dump_file, "\n");
            }
            const bool to_truth = e > truth_above_px || truth_at == "found" ||
                                  (truth_at == "outline" && outline) ||
                                  (truth_at == "inner" && !outline);
            const auto it =
                given.find(variant + " " + std::to_string(v) + " " + std::to_string(c.id));
            if (it != given.end())
              solved_corners.push_back({c.id, it->second});
            else if (to_truth)
              solved_corners.push_back(
                  {c.id, view.truth[c.id] +
                             truth_noise_px * Eigen::Vector2d(rng.gaussian(1), rng.gaussian(1))});
            else
              solved_corners.push_back(c);
          }
          if (per_view)
            std::printf(
                "  view %2zu level %.3f shift %.3f edged %d dropped %d | outline %d rms %.3f out "
                "%.3f "
                "| others %d rms %.3f out %.3f\n",
                v, d.tag_edge_level, d.tag_edge_shift_px, d.corners_from_edges,
                d.corners_inconsistent, view_n[1], std::sqrt(view_sq[1] / std::max(1, view_n[1])),
                view_out[1] / std::max(1, view_n[1]), view_n[0],
                std::sqrt(view_sq[0] / std::max(1, view_n[0])),
                view_out[0] / std::max(1, view_n[0]));
          if (truth_corners) {
            std::vector<CornerObservation> truth;
            for (int id = 0; id < spec.NumCorners(); ++id) truth.push_back({id, view.truth[id]});
            used_views.push_back({"view" + std::to_string(v), truth});
          } else if (d.found) {
            used_views.push_back({"view" + std::to_string(v), solved_corners});
          }
          if (verbose || (!d.found && aruco_reads))
            std::printf("  %s view %2zu: ours %2d tags (%s), aruco %2zu, %.0f ms\n", name.c_str(),
                        v, d.tags, d.found ? "used" : d.reason.c_str(), aruco.size(), t_ms);
        }
        all_lost += lost;
        std::printf(
            "%s: %zu views, used %d, lost %d (aruco >= 4 tags in %d), tags ours %d aruco %d, "
            "detect %.0f ms/view (max %.0f), corners rms %.3f px (worst %.2f, mean %.3f %.3f, "
            "radial %.3f, out of the tag %.3f)",
            name.c_str(), poses.size(), used, lost, aruco_ok, tags_ours, tags_aruco,
            ms / std::max<size_t>(1, poses.size()), ms_max, std::sqrt(sq_px / std::max(1, corners)),
            worst_px, sum_px.x() / std::max(1, corners), sum_px.y() / std::max(1, corners),
            sum_radial_px / std::max(1, corners), sum_outward_px / std::max(1, corners));
        std::printf(", outline corners %d rms %.3f out %.3f, others %d rms %.3f out %.3f",
                    outline_n, std::sqrt(outline_sq / std::max(1, outline_n)),
                    outline_out / std::max(1, outline_n), inner_n,
                    std::sqrt(inner_sq / std::max(1, inner_n)), inner_out / std::max(1, inner_n));
        std::printf(", border misread in %d views, mostly second look in %d", border_misread,
                    mostly_second_look);
        if (solve && used >= kMinViews) {
          CalibrateRequest request;
          request.board = spec;
          request.model = "opencv4";
          request.cross_validate = false;
          CalibrationRun run;
          run.width = lens.width, run.height = lens.height, run.views = used_views;
          // A solve holds GBs (40 views of 144 corners): runs side by side take turns.
          FILE* lock = solve_lock.empty() ? nullptr : std::fopen(solve_lock.c_str(), "a");
          if (lock != nullptr) flock(fileno(lock), LOCK_EX);
          const fresco::Status s = SolveViews(request, &run);
          if (s.ok()) {
            const double rms =
                ProjectionDifference_px("LENSMODEL_OPENCV4", lens.intrinsics,
                                        run.Chosen().lensmodel, run.Chosen().fit.intrinsics, grid);
            std::vector<cv::Point2f> seen, hull;
            for (const BoardView& bv : used_views)
              for (const CornerObservation& c : bv.corners)
                seen.emplace_back(static_cast<float>(c.pixel.x()), static_cast<float>(c.pixel.y()));
            cv::convexHull(seen, hull);
            std::vector<Eigen::Vector2d> inside;
            for (const Eigen::Vector2d& g : grid)
              if (cv::pointPolygonTest(hull, cv::Point2f(g.x(), g.y()), false) >= 0)
                inside.push_back(g);
            const double rms_seen = ProjectionDifference_px("LENSMODEL_OPENCV4", lens.intrinsics,
                                                            run.Chosen().lensmodel,
                                                            run.Chosen().fit.intrinsics, inside);
            std::printf(
                ", lens vs truth %.3f px rms (where seen %.3f, %zu of %zu points) (fx %.2f)", rms,
                rms_seen, inside.size(), grid.size(), run.Chosen().fit.intrinsics[0]);
          } else {
            std::printf(", solve failed: %s", s.message().c_str());
          }
          if (lock != nullptr) std::fclose(lock);  // and its lock
        }
        std::printf("\n");
        std::fflush(stdout);
      }
  }
  if (dump_file != nullptr) std::fclose(dump_file);
  std::printf("lost in all: %d\n", all_lost);
  return 0;
}
