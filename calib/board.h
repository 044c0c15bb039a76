// Calibration boards: the spec string, the physical corner positions (metres), and how the
// corners map onto mrcal's regular board grid.
//
// Specs (docs/contract.md):
//   chessboard:COLSxROWS:SQUARE_M        inner corners, e.g. chessboard:9x6:0.025
//   aprilgrid:COLSxROWS:TAG_M:SPACING    Kalibr AprilGrid of tag36h11, e.g. aprilgrid:6x6:0.088:0.3
//
// Board frame (both kinds): z = 0 on the board, metres.
// - Chessboard: corner id = row * COLS + col in OpenCV's findChessboardCorners order, at
//   (col * SQUARE_M, row * SQUARE_M, 0).
// - AprilGrid, Kalibr's convention (checked against the reference detections of
//   aprilgrid-yac-mocap, where yac writes the board point of every corner): tag id =
//   row * COLS + col, tag 0 at the origin, ids grow along +x then row by row along +y (on the
//   printed board +x is right and +y is up, so tag 0 is at the bottom-left). The tag pitch
//   is TAG_M * (1 + SPACING). Corner k of a tag (k = 0..3) is at tag origin + (0,0), (TAG_M,0),
//   (TAG_M,TAG_M), (0,TAG_M): the apriltag library's p[0..3] order (bottom-left,
//   bottom-right, top-right, top-left of the black square on the upright tag). Corner id =
//   tag id * 4 + k.
// mrcal models a board as a regular W x H grid of points (spacing d). A chessboard is one;
// an AprilGrid's corners are not, so they are placed on a finer regular grid (d = TAG_M / q,
// q the smallest integer with SPACING * q whole) whose other points are never observed.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pipeline/core/status.h"

namespace fresco::calib {

enum class BoardKind { kChessboard, kAprilGrid };

struct BoardSpec {
  BoardKind kind = BoardKind::kChessboard;
  int cols = 0;           // chessboard: inner corners per row; aprilgrid: tags per row
  int rows = 0;           // chessboard: inner corners per column; aprilgrid: tags per column
  double square_m = 0;    // chessboard square edge; aprilgrid: tag edge (black square)
  double spacing = 0;     // aprilgrid: gap between tags / tag edge
  std::string text;       // the spec as given

  int NumCorners() const { return kind == BoardKind::kChessboard ? cols * rows : cols * rows * 4; }
  double TagPitch_m() const { return square_m * (1 + spacing); }
};

// Parses a board spec; errors name `what` (e.g. "--board") and the field.
Status ParseBoardSpec(const std::string& text, const std::string& what, BoardSpec* spec);

// Physical position of corner `id` on the board (metres, z = 0).
Eigen::Vector3d CornerPosition(const BoardSpec& spec, int id);

// mrcal's regular grid for a board: width_n x height_n points, `spacing_m` apart.
struct BoardGrid {
  int width_n = 0;
  int height_n = 0;
  double spacing_m = 0;
  std::vector<int> grid_index_of_corner;  // (NumCorners) index j * width_n + i in the grid
};
BoardGrid MakeBoardGrid(const BoardSpec& spec);

// Outer size of the board's pattern (metres): chessboard squares incl. the outer ones,
// AprilGrid from the first tag's outer edge to the last's.
Eigen::Vector2d PatternSize_m(const BoardSpec& spec);

}  // namespace fresco::calib
