#include "calib/detect.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <vector>

#include <Eigen/Dense>

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/detect_aruco.h"
#include "calib/kalibr_tag_family.h"
#include "calib/tag_corner_edges.h"
#include "calib/tag_dilation.h"
#include "calib/tags_around_found.h"

namespace fresco::calib {
namespace {

// cornerSubPix half-window for a chessboard: 40 % of the shortest distance between
// neighbouring corners (so the window holds one saddle), 3..11 px.
int ChessboardHalfWindow(const std::vector<cv::Point2f>& corners, const BoardSpec& spec) {
  double shortest = 1e9;
  for (int r = 0; r < spec.rows; ++r)
    for (int c = 0; c + 1 < spec.cols; ++c)
      shortest = std::min(shortest, static_cast<double>(cv::norm(corners[r * spec.cols + c + 1] -
                                                                 corners[r * spec.cols + c])));
  return std::clamp(static_cast<int>(0.4 * shortest), 3, 11);
}

// findChessboardCorners + cornerSubPix first (on opencv-chessboard-stereo it reproduces
// OpenCV's reference calibration; findChessboardCornersSB's corners moved fx by -0.8 %),
// findChessboardCornersSB when the classic detector fails.
BoardDetection DetectChessboard(const cv::Mat& gray, const BoardSpec& spec,
                                const DetectOptions& options) {
  BoardDetection out;
  const cv::Size pattern(spec.cols, spec.rows);
  std::vector<cv::Point2f> corners;
  bool found = cv::findChessboardCorners(
      gray, pattern, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
  if (found) {
    const int half = ChessboardHalfWindow(corners, spec);
    cv::cornerSubPix(gray, corners, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.01));
  } else {
    found = cv::findChessboardCornersSB(gray, pattern, corners,
                                        cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_ACCURACY);
  }
  if (!found) {
    out.reason = "chessboard " + std::to_string(spec.cols) + "x" + std::to_string(spec.rows) +
                 " not found (findChessboardCorners and findChessboardCornersSB)";
    return out;
  }
  for (size_t k = 0; k < corners.size(); ++k)
    out.corners.push_back({static_cast<int>(k), Eigen::Vector2d(corners[k].x, corners[k].y)});
  out.found = true;
  return out;
}

// A tag corner cornerSubPix moved further than this from the outline read (no black square
// at it: calib/tag_corner_edges.h) is looked for from the outline.
constexpr double kStrayedPx = 1.0;

// Half-size of cornerSubPix's window for a tag: its shortest edge in the image over
// `edge_over_half` (8: the window a quarter of it, so it never reaches the next corner of the
// same tag), at least 2, at most 6.
constexpr double kEdgeOverHalf = 8;
// With Kalibr's crossing squares: the next saddle is across the square, 0.3 tag edges away;
// a half-window of a seventh of the edge (0.14) stays short of the square's middle (0.15).
// Against the quarter: on 10 of the yac photos the corners' median distance from yac's
// 0.096 -> 0.088 px, the opencv4 fit of all 30 0.271 -> 0.252 px rms; synthetic Kalibr
// boards, blurred 1 px, 0.091 -> 0.073 px rms from the truth (sharp 0.136 -> 0.135 px).
constexpr double kEdgeOverHalfWithSquares = 7;
// Where the two windows' saddles lie further apart than this, neither is trusted: the corner
// is left out (one window reached another feature, a foreshortened tag's next saddle; synthetic
// Kalibr boards under a strong barrel lens, blurred 1 px, the worst corner 2.93 / 2.22 px
// from the truth with either window kept, 0.97 / 1.45 px so).
constexpr double kWindowsAgreePx = 0.5;
int RefineHalfWindow(const TagQuad& quad, double edge_over_half) {
  double shortest = 1e9;
  for (int k = 0; k < 4; ++k)
    shortest = std::min(shortest, (quad.p[(k + 1) % 4] - quad.p[k]).norm());
  return std::clamp(static_cast<int>(shortest / edge_over_half), 2, 6);
}

// The tag's corners moved onto the image's saddles (cornerSubPix). A corner whose start lies
// too far from its saddle is left where it started (OpenCV keeps the start when the estimate
// leaves its window): such a start came from a tag outline traced under strong distortion or
// on a thinned image, and lies 2-8 px off. Those corners are left out (`refined` false): a
// corner fewer costs the solve little, one several pixels off biases it. (Retrying them from
// where the tag's other corners put them recovered a third of them, but one in six of those
// settled on the wrong saddle.)
void RefineTagCorners(const cv::Mat& gray, const TagQuad& quad, double edge_over_half,
                      std::vector<cv::Point2f>* corners, bool refined[4]) {
  const int half = RefineHalfWindow(quad, edge_over_half);
  const std::vector<cv::Point2f> start = *corners;
  cv::cornerSubPix(gray, *corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 40, 1e-3));
  for (int k = 0; k < 4; ++k) refined[k] = (*corners)[k] != start[k];
}

// Whether corner i lies where the corners near it on the board (those with `usable` set)
// place it: x and y each a quadratic in the board coordinates (in tag pitches) about it
// (perspective and lens distortion over a few tags), fitted by least squares to the corners
// within 1.05 pitches (up to twice that where fewer than 12 are), then again without the
// neighbours it explains worst (a wrong neighbour); within 1.5 px or 4 % of the local pitch.
// `undecided` when too few neighbours are there to tell.
bool WhereItsNeighboursPlaceIt(const std::vector<CornerObservation>& corners,
                               const std::vector<Eigen::Vector2d>& board,
                               const std::vector<uint8_t>& usable, size_t i, bool undecided) {
  constexpr size_t kMinNeighbours = 12;
  constexpr double kReachPitches = 1.05, kLimitPx = 1.5, kLimitOfPitch = 0.04;
  std::vector<Eigen::Vector2d> from, to;
  for (double reach : {kReachPitches, 1.5 * kReachPitches, 2 * kReachPitches}) {
    from.clear(), to.clear();
    for (size_t j = 0; j < corners.size(); ++j) {
      if (j == i || !usable[j] || (board[j] - board[i]).norm() > reach) continue;
      from.push_back(board[j] - board[i]);
      to.push_back(corners[j].pixel);
    }
    if (from.size() >= kMinNeighbours) break;
  }
  if (from.size() < kMinNeighbours) return undecided;
  const auto terms = [](const Eigen::Vector2d& b) {
    return (Eigen::Matrix<double, 6, 1>() << 1, b.x(), b.y(), b.x() * b.x(), b.x() * b.y(),
            b.y() * b.y())
        .finished();
  };
  Eigen::Matrix<double, 6, 2> coefficients;
  const auto fit = [&](const std::vector<uint8_t>& use) {
    const int n = static_cast<int>(std::count(use.begin(), use.end(), 1));
    if (n < 9) return false;
    Eigen::MatrixXd a(n, 6), b(n, 2);
    for (size_t j = 0, row = 0; j < from.size(); ++j)
      if (use[j]) a.row(row) = terms(from[j]).transpose(), b.row(row++) = to[j].transpose();
    coefficients = a.colPivHouseholderQr().solve(b);
    return true;
  };
  std::vector<uint8_t> use(from.size(), 1);
  if (!fit(use)) return undecided;
  std::vector<double> errors(from.size());
  for (size_t j = 0; j < from.size(); ++j)
    errors[j] = (coefficients.transpose() * terms(from[j]) - to[j]).norm();
  std::vector<double> sorted = errors;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double cut = std::max(0.5, 4 * sorted[sorted.size() / 2]);
  for (size_t j = 0; j < from.size(); ++j) use[j] = errors[j] <= cut;
  if (!fit(use)) return undecided;
  // At the corner itself (board offset 0) the quadratic is its constant term; the local pitch
  // in pixels is the square root of the linear terms' determinant.
  const Eigen::Vector2d predicted = coefficients.row(0).transpose();
  const double pitch_px = std::sqrt(
      std::abs(coefficients(1, 0) * coefficients(2, 1) - coefficients(2, 0) * coefficients(1, 1)));
  return (predicted - corners[i].pixel).norm() <= std::max(kLimitPx, kLimitOfPitch * pitch_px);
}

// Drops the corners the board's other corners near them place elsewhere: cornerSubPix can
// settle on a point of a tag's edge instead of its corner (a foreshortened tag under strong
// distortion), several pixels off. A corner found out of place is judged again from the
// corners found in place only (a wrong neighbour can put a right corner out of place).
// Returns how many were dropped.
int DropCornersTheirNeighboursPlaceElsewhere(const BoardSpec& spec,
                                             std::vector<CornerObservation>* corners) {
  const double pitch = spec.TagPitch_m();
  std::vector<Eigen::Vector2d> board(corners->size());
  for (size_t i = 0; i < corners->size(); ++i)
    board[i] = CornerPosition(spec, (*corners)[i].id).head<2>() / pitch;
  const std::vector<uint8_t> all(corners->size(), 1);
  std::vector<uint8_t> in_place(corners->size(), 1);
  for (size_t i = 0; i < corners->size(); ++i)
    in_place[i] = WhereItsNeighboursPlaceIt(*corners, board, all, i, true);
  std::vector<uint8_t> keep = in_place;
  for (size_t i = 0; i < corners->size(); ++i)
    if (!in_place[i]) keep[i] = WhereItsNeighboursPlaceIt(*corners, board, in_place, i, false);
  size_t kept = 0;
  for (size_t i = 0; i < corners->size(); ++i)
    if (keep[i]) (*corners)[kept++] = (*corners)[i];
  const int dropped = static_cast<int>(corners->size() - kept);
  corners->resize(kept);
  return dropped;
}

}  // namespace

std::vector<TagQuad> DetectTagsApriltag(const cv::Mat& gray, int num_ids,
                                        const DetectOptions& options) {
  // Kalibr's tags (2-bit border) and the library's own tag36h11 (1-bit border): the same
  // codes; the detector decodes every quad against both.
  KalibrTagFamily kalibr;
  apriltag_family_t* one_bit = tag36h11_create();
  apriltag_detector_t* detector = apriltag_detector_create();
  if (options.border_bits != 1)
    apriltag_detector_add_family_bits(detector, kalibr.get(), options.max_hamming);
  if (options.border_bits != 2)
    apriltag_detector_add_family_bits(detector, one_bit, options.max_hamming);
  detector->quad_decimate = static_cast<float>(options.quad_decimate);
  detector->nthreads = 1;
  detector->refine_edges = 1;
  cv::Mat contiguous = gray.isContinuous() ? gray : gray.clone();
  image_u8_t image = {contiguous.cols, contiguous.rows, static_cast<int32_t>(contiguous.step),
                      contiguous.data};
  zarray_t* detections = apriltag_detector_detect(detector, &image);
  std::vector<TagQuad> quads;
  for (int i = 0; i < zarray_size(detections); ++i) {
    apriltag_detection_t* det = nullptr;
    zarray_get(detections, i, &det);
    if (det->id >= num_ids || det->hamming > options.max_hamming) continue;
    TagQuad quad;
    quad.id = det->id;
    quad.border_bits = det->family == one_bit ? 1 : 2;
    for (int k = 0; k < 4; ++k) quad.p[k] = Eigen::Vector2d(det->p[k][0], det->p[k][1]);
    quads.push_back(quad);
  }
  apriltag_detections_destroy(detections);
  apriltag_detector_destroy(detector);
  tag36h11_destroy(one_bit);
  // A Kalibr tag whose border thinned (a thinned image, blur) can read as a 1-bit tag of the
  // same id inside it: one tag, the outer square its outline.
  const auto area = [](const TagQuad& q) {
    return std::abs((q.p[2] - q.p[0]).x() * (q.p[3] - q.p[1]).y() -
                    (q.p[2] - q.p[0]).y() * (q.p[3] - q.p[1]).x());
  };
  const auto centre = [](const TagQuad& q) { return 0.25 * (q.p[0] + q.p[1] + q.p[2] + q.p[3]); };
  for (size_t i = 0; i < quads.size(); ++i)
    for (size_t j = i + 1; j < quads.size(); ++j) {
      if (quads[i].id != quads[j].id || quads[i].border_bits == quads[j].border_bits) continue;
      const double edge = std::sqrt(std::max(area(quads[i]), area(quads[j])) / 2);
      if ((centre(quads[i]) - centre(quads[j])).norm() > 0.25 * edge) continue;
      if (area(quads[j]) > area(quads[i])) std::swap(quads[i], quads[j]);
      quads.erase(quads.begin() + j--);
    }
  if (options.keep_repeated_ids) return quads;
  std::map<int, int> count_by_id;
  for (const TagQuad& q : quads) ++count_by_id[q.id];
  quads.erase(std::remove_if(quads.begin(), quads.end(),
                             [&](const TagQuad& q) { return count_by_id[q.id] > 1; }),
              quads.end());
  return quads;
}

namespace {

// Adds the quads of ids not in `found` yet; returns how many.
int AddMissing(const std::vector<TagQuad>& quads, std::map<int, TagQuad>* found) {
  std::map<int, int> count_by_id;
  for (const TagQuad& q : quads) ++count_by_id[q.id];
  int added = 0;
  for (const TagQuad& q : quads)
    if (count_by_id[q.id] == 1 && found->emplace(q.id, q).second) ++added;
  return added;
}

// The border the tags read so far have (the most of them), or 0 when none was read.
int BorderBitsOf(const std::map<int, TagQuad>& found) {
  int by_bits[3] = {0, 0, 0};
  for (const auto& [id, quad] : found) ++by_bits[quad.border_bits == 1 ? 1 : 2];
  if (by_bits[1] + by_bits[2] == 0) return 0;
  return by_bits[1] > by_bits[2] ? 1 : 2;
}

// The edge level is looked for (DetectAprilGrid) when the tags at level 0.5 are grown or
// shrunk by more than kLevelSearchFromPx, from a second level kLevelStep away; it is kept
// within kMinLevel..kMaxLevel (gamma 2: about 0.38, gamma 0.5: about 0.62).
constexpr double kLevelSearchFromPx = 0.02, kLevelStep = 0.12;
constexpr double kMinLevel = 0.2, kMaxLevel = 0.8;

// A tag's corners moved onto the image's saddles (RefineTagCorners), and which settled.
struct Saddles {
  std::array<Eigen::Vector2d, 4> p;
  bool refined[4] = {true, true, true, true};
};

// The corners of the tags `found`: each the saddle, or where no black square is at it, where the
// tag's edges through it meet, each edge where its cuts cross `level` between the edge's dark
// and light levels (calib/tag_corner_edges.h); corners sorted by id, `edged_ids` those from the
// edges. Returns how many are. `border_bits`: the board's (BorderBitsOf).
// On a board with crossing squares (`squares`), a saddle that strayed where the square shows
// at the outline is left out: cornerSubPix failed at a real saddle (the board's outermost
// corners on the yac photos: the square's contact with the tag blurred to grey), and the
// tag's edges run on into the square's there, so they do not give the corner either.
int PlaceCorners(const cv::Mat& gray, const std::map<int, TagQuad>& found,
                 const std::map<int, Saddles>& saddles, const DetectOptions& options, double level,
                 bool squares, int border_bits, std::vector<CornerObservation>* out_corners,
                 std::set<int>* edged_ids) {
  out_corners->clear();
  edged_ids->clear();
  for (const auto& [id, quad] : found) {
    const Saddles& saddle = saddles.at(id);
    std::array<Eigen::Vector2d, 4> corners = saddle.p;
    bool refined[4];
    std::copy(saddle.refined, saddle.refined + 4, refined);
    if (options.refine_tag_corners) {
      // Where the board has no black square at a corner, cornerSubPix's saddle is not there:
      // the corner from the tag's edges (calib/tag_corner_edges.h).
      const std::array<Eigen::Vector2d, 4>& p = saddle.p;
      std::array<std::array<double, 2>, 4> levels;
      bool placed[4] = {false, false, false, false};
      for (int k = 0; k < 4; ++k) {
        Eigen::Vector2d corner;
        // No square, and the saddle more than 1 px from the tag's outline as read: near a
        // narrow paper margin on a dark surround cornerSubPix settles 2-6 px off, on the
        // paper's edge, and edges looked for from there are the paper's. Then the edges are
        // looked for from the outline.
        const bool strayed =
            options.edges_from_outline_when_strayed && (p[k] - quad.p[k]).norm() > kStrayedPx;
        const std::array<Eigen::Vector2d, 4>& from = strayed ? quad.p : p;
        if (!refined[k] || CrossingSquareAt(gray, p, k)) continue;
        if (squares && strayed && CrossingSquareAt(gray, quad.p, k)) {
          refined[k] = false;
          continue;
        }
        bool left_out = false;
        if (!CornerFromEdges(gray, from, k, &corner, &left_out, &levels[k], level, border_bits)) {
          refined[k] = !strayed && !left_out;  // a stray saddle and no edges: left out
          continue;
        }
        corners[k] = corner;
        placed[k] = true;
      }
      // The board's own corners: both edges beside the paper margin, no gap's white beside
      // either to tell a margin too narrow for its blur by; the tag's other corners' is.
      double tag_light = 0;
      for (int k = 0; k < 4; ++k)
        if (placed[k]) tag_light = std::max(tag_light, levels[k][1]);
      for (int k = 0; k < 4; ++k) {
        if (!placed[k]) continue;
        if (tag_light - levels[k][1] > kMaxEdgeLightDeficit * (tag_light - levels[k][0])) {
          refined[k] = false;
          continue;
        }
        edged_ids->insert(id * 4 + k);
      }
    }
    for (int k = 0; k < 4; ++k)
      if (refined[k]) out_corners->push_back({id * 4 + k, corners[k]});
  }
  std::sort(out_corners->begin(), out_corners->end(),
            [](const CornerObservation& a, const CornerObservation& b) { return a.id < b.id; });
  return static_cast<int>(edged_ids->size());
}

// Each tag's corners moved onto the image's saddles from its outline (RefineTagCorners, the
// window the tag's shortest edge over `edge_over_half`), or the outline when not refining.
std::map<int, Saddles> FindSaddles(const cv::Mat& gray, const std::map<int, TagQuad>& found,
                                   const DetectOptions& options, double edge_over_half) {
  std::map<int, Saddles> saddles;
  for (const auto& [id, quad] : found) {
    Saddles& t = saddles[id];
    std::vector<cv::Point2f> corners;
    for (int k = 0; k < 4; ++k)
      corners.emplace_back(static_cast<float>(quad.p[k].x()), static_cast<float>(quad.p[k].y()));
    if (options.refine_tag_corners)
      RefineTagCorners(gray, quad, edge_over_half, &corners, t.refined);
    for (int k = 0; k < 4; ++k) t.p[k] = Eigen::Vector2d(corners[k].x, corners[k].y);
  }
  return saddles;
}

// Whether the board prints Kalibr's squares where the gaps cross: one shows at more than half
// of the saddles found within 1 px of the outline (yac's photos: 73-135 of 74-136 each; the
// OpenCV-drawn boards of calib_detect_elsewhere, every variant: on no view).
bool HasCrossingSquares(const cv::Mat& gray, const std::map<int, TagQuad>& found,
                        const std::map<int, Saddles>& saddles) {
  int probed = 0, squares = 0;
  for (const auto& [id, quad] : found) {
    const Saddles& t = saddles.at(id);
    for (int k = 0; k < 4; ++k) {
      if (!t.refined[k] || (t.p[k] - quad.p[k]).norm() > kStrayedPx) continue;
      ++probed;
      squares += CrossingSquareAt(gray, t.p, k);
    }
  }
  return squares > probed / 2;
}

BoardDetection DetectAprilGrid(const cv::Mat& gray, const BoardSpec& spec,
                               const DetectOptions& options) {
  BoardDetection out;
  const int num_ids = spec.cols * spec.rows;
  std::map<int, TagQuad> found;
  out.tags_library = AddMissing(DetectTagsApriltag(gray, num_ids, options), &found);
  // OpenCV's aruco on every image: it thresholds and traces contours differently and reads
  // tags the library misses (and the other way round). With the border the library's tags
  // have, or the one asked for; both when neither tells.
  std::vector<int> aruco_borders = {options.border_bits};
  if (!options.second_look) {
    aruco_borders.clear();
  } else if (options.border_bits == 0) {
    const int seen = BorderBitsOf(found);
    aruco_borders = seen ? std::vector<int>{seen} : std::vector<int>{2, 1};
  }
  for (int bits : aruco_borders) {
    const std::vector<TagQuad> aruco = DetectTagsAruco(gray, num_ids, bits);
    out.tags_aruco += static_cast<int>(aruco.size());
    out.tags_aruco_only += AddMissing(aruco, &found);
  }
  if (options.second_look && static_cast<int>(found.size()) < num_ids) {
    // Second look for the missing tags. Kalibr prints a black square where the gaps between
    // tags cross; it touches the corners of 4 tags, so the library's segmentation merges the
    // board's black into one blob and finds few tag outlines (a whole board under a strong
    // barrel distortion: 1 tag of 36). Thinning the black (a grey dilation) cuts those
    // contacts; the quads found on the thinned image are refined on the original below.
    for (int grow : {3, 5}) {
      if (static_cast<int>(found.size()) >= num_ids) break;
      cv::Mat thinned;
      cv::dilate(gray, thinned, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(grow, grow)));
      out.tags_second_look += AddMissing(DetectTagsApriltag(thinned, num_ids, options), &found);
    }
    if (static_cast<int>(found.size()) < num_ids)
      out.tags_second_look += FindTagsAroundFound(
          gray, spec,
          [&](const cv::Mat& patch) { return DetectTagsApriltag(patch, num_ids, options); },
          &found);
  }
  out.border_bits = BorderBitsOf(found);
  for (const auto& [id, quad] : found)
    out.tag_centres.push_back(0.25 * (quad.p[0] + quad.p[1] + quad.p[2] + quad.p[3]));
  // The saddles (cornerSubPix); on a board with crossing squares again with the wider window,
  // each kept where the quarter's agrees within kWindowsAgreePx; the corners from the tags'
  // edges at an edge level.
  std::map<int, Saddles> saddles = FindSaddles(gray, found, options, kEdgeOverHalf);
  if (options.refine_tag_corners && options.saddles_for_crossing_squares &&
      HasCrossingSquares(gray, found, saddles)) {
    out.crossing_squares = true;
    const std::map<int, Saddles> wider =
        FindSaddles(gray, found, options, kEdgeOverHalfWithSquares);
    for (auto& [id, saddle] : saddles) {
      const Saddles& w = wider.at(id);
      for (int k = 0; k < 4; ++k) {
        if (!w.refined[k] || !saddle.refined[k] || (w.p[k] - saddle.p[k]).norm() > kWindowsAgreePx)
          saddle.refined[k] = false;
        saddle.p[k] = w.p[k];
      }
    }
  }
  std::vector<bool> from_edges;
  const auto place = [&](double level, std::vector<CornerObservation>* placed_corners) {
    std::set<int> edged_ids;
    const int from_edges_count =
        PlaceCorners(gray, found, saddles, options, level, out.crossing_squares, out.border_bits,
                     placed_corners, &edged_ids);
    from_edges.clear();
    for (const CornerObservation& c : *placed_corners)
      from_edges.push_back(edged_ids.count(c.id) > 0);
    return from_edges_count;
  };
  out.corners_from_edges = place(0.5, &out.corners);
  out.tags = static_cast<int>(found.size());
  if (out.corners_from_edges > 0) {  // a tone curve grows or shrinks the tags: tag_dilation.h
    out.tag_edge_shift_px = TagEdgeShift_px(spec, out.corners, from_edges);
    // The edge level at which the tags are neither grown nor shrunk, from the shifts at two
    // levels (the secant); each edge then moves by its own ramp's share of the tone curve.
    if (options.edge_level_from_pitch && std::abs(out.tag_edge_shift_px) > kLevelSearchFromPx) {
      const double level_0 = 0.5, shift_0 = out.tag_edge_shift_px;
      const double level_1 = level_0 + (shift_0 > 0 ? -kLevelStep : kLevelStep);
      std::vector<CornerObservation> at_1;
      place(level_1, &at_1);
      const double shift_1 = TagEdgeShift_px(spec, at_1, from_edges);
      // A lower level moves the edges into the dark, inwards: the shift must fall with it.
      if ((shift_1 - shift_0) * (level_1 - level_0) > 0 && shift_1 != 0) {
        const double level = std::clamp(
            level_0 - shift_0 * (level_1 - level_0) / (shift_1 - shift_0), kMinLevel, kMaxLevel);
        out.corners_from_edges = place(level, &out.corners);
        out.tag_edge_level = level;
        out.tag_edge_shift_px = TagEdgeShift_px(spec, out.corners, from_edges);
      } else {
        place(level_0, &out.corners);
      }
    }
    ShiftTagEdges(out.tag_edge_shift_px, from_edges, &out.corners, &found);
  }
  if (options.refine_tag_corners && options.drop_inconsistent_corners)
    out.corners_inconsistent = DropCornersTheirNeighboursPlaceElsewhere(spec, &out.corners);
  if (out.tags == 0) {
    out.corners.clear();
    out.reason = "no tag36h11 tag of the board (ids 0.." + std::to_string(num_ids - 1) + ") found";
  } else if (static_cast<int>(out.corners.size()) < options.min_corners) {
    out.reason = "only " + std::to_string(out.tags) + " tag(s) found (need " +
                 std::to_string((options.min_corners + 3) / 4) + ")";
    out.corners.clear();
  } else {
    out.found = true;
  }
  return out;
}

}  // namespace

BoardDetection DetectBoard(const cv::Mat& gray, const BoardSpec& spec,
                           const DetectOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  BoardDetection out = spec.kind == BoardKind::kChessboard ? DetectChessboard(gray, spec, options)
                                                           : DetectAprilGrid(gray, spec, options);
  out.detect_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace fresco::calib
