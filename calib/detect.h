// Board detection in one image: per-corner pixel observations with their corner ids
// (calib/board.h), partial boards included. AprilGrid: the apriltag library and OpenCV's
// aruco on every image, every tag either reads kept (tag36h11 with Kalibr's 2-bit black
// border or the 1-bit border OpenCV and the apriltag library draw); when they miss some of
// the board's tags, a second look for the missing ones (the apriltag library on a thinned
// image, then around the tags found: calib/tags_around_found.h); then optionally
// cv::cornerSubPix on each tag corner, whichever detector found it. Chessboard: OpenCV's
// findChessboardCornersSB, falling back to findChessboardCorners + cornerSubPix.
// Pixel convention: (0,0) is the centre of the top-left pixel (apriltag, OpenCV and mrcal).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "calib/board.h"
#include "calib/detect_aruco.h"

namespace fresco::calib {

struct CornerObservation {
  int id = 0;             // corner id on the board (calib/board.h)
  Eigen::Vector2d pixel;  // (0,0) = centre of the top-left pixel
};

struct BoardDetection {
  bool found = false;
  std::string reason;  // why not found (one line), empty when found
  std::vector<CornerObservation> corners;
  int tags = 0;              // AprilGrid: tags kept
  int tags_library = 0;      // AprilGrid: tags the apriltag library read on the image itself
  int tags_aruco = 0;        // AprilGrid: tags OpenCV's aruco read
  int tags_aruco_only = 0;   // AprilGrid: of the tags kept, read by aruco alone
  int tags_second_look = 0;  // AprilGrid: of the tags kept, found by the second look
  int border_bits = 0;       // AprilGrid: the tags' black border (1 or 2; 0: no tag read)
  // AprilGrid: corners placed where the tag's edges meet (no black square at the corner:
  // calib/tag_corner_edges.h) instead of on cornerSubPix's saddle.
  int corners_from_edges = 0;
  // AprilGrid: where between the edges' dark (0) and light (1) levels those corners' edges
  // were placed: 0.5, or the level at which a tone curve leaves the tags neither grown nor
  // shrunk (calib/tag_dilation.h).
  double tag_edge_level = 0.5;
  // AprilGrid: how far (px, outwards) the edges at that level still lay from where the tags'
  // pitch puts them, undone (calib/tag_dilation.h); 0 when not measured.
  double tag_edge_shift_px = 0;
  double detect_ms = 0;  // wall time of this detection
  // AprilGrid: the centre of every tag read (before corners were left out), for marking
  // where a rejected image saw the board.
  std::vector<Eigen::Vector2d> tag_centres;
  // AprilGrid: corners dropped because the corners near them on the board place them more
  // than 1.5 px (or 4 % of a tag pitch) elsewhere (settled on a tag's edge, not its corner).
  int corners_inconsistent = 0;
  // AprilGrid: the board prints Kalibr's black squares where the gaps cross (most tag corners
  // show one), so every tag corner is a saddle: DetectOptions::saddles_for_crossing_squares.
  bool crossing_squares = false;
};

struct DetectOptions {
  // AprilGrid: refine each tag corner with cv::cornerSubPix (window scaled to the tag size).
  bool refine_tag_corners = true;
  // AprilGrid: drop refined corners that the corners near them on the board place elsewhere
  // (BoardDetection::corners_inconsistent).
  bool drop_inconsistent_corners = true;
  double quad_decimate = 1.0;  // apriltag: 1 keeps full resolution (small tags need it)
  int max_hamming = 1;         // apriltag: bit errors accepted per tag
  int min_corners = 8;         // fewer than this: not found
  // AprilGrid: the tags' black border in bits: 0 reads either, 2 only Kalibr's, 1 only the
  // one OpenCV (GridBoard, drawMarker) and the apriltag library's own images have.
  int border_bits = 0;
  // AprilGrid: OpenCV's aruco besides the apriltag library, and when they miss tags of the
  // board, look again for the missing ones (false: the library alone). Under a strong lens
  // distortion the library loses whole boards (tag edges bent away from its straight quad
  // sides: the bits it samples drift off their cells); see tests/calib/calib_detect_test.cc
  // and tests/calib/calib_detect_elsewhere_test.cc for the figures.
  bool second_look = true;
  // AprilGrid: where no black square is at a tag corner and cornerSubPix moved it more than
  // 1 px from the outline read, its edges are looked for from the outline (the corner left
  // out when none show) instead of from the saddle (on a paper's or a tag's edge).
  bool edges_from_outline_when_strayed = true;
  // AprilGrid: on a board with crossing squares (BoardDetection::crossing_squares), the
  // saddles found again with a window up to the square's middle (a corner the two windows
  // place more than 0.5 px apart left out), and a corner whose saddle strayed more than 1 px
  // from the outline where the square shows at the outline left out (false: every board
  // alike, a window a quarter of the tag's edge, such corners from the edges).
  bool saddles_for_crossing_squares = true;
  // AprilGrid: the tags' edges placed at the level (between each edge's dark and light) that
  // keeps the tags neither grown nor shrunk against their pitch (BoardDetection::
  // tag_edge_level); false: halfway, the shift measured there undone alike at every edge.
  bool edge_level_from_pitch = true;
  // DetectTagsApriltag: keep every tag read, an id read twice too (photos of scattered tags
  // of one id; a board has each id once, so by default both are dropped).
  bool keep_repeated_ids = false;
};

// One run of the apriltag library (tag36h11 with the black border options.border_bits
// allows): tags with ids < num_ids and at most options.max_hamming bit errors, unrefined; an
// id found twice is dropped (trust neither) unless options.keep_repeated_ids.
std::vector<TagQuad> DetectTagsApriltag(const cv::Mat& gray, int num_ids,
                                        const DetectOptions& options = {});

// `gray` is CV_8U.
BoardDetection DetectBoard(const cv::Mat& gray, const BoardSpec& spec,
                           const DetectOptions& options = {});

}  // namespace fresco::calib
