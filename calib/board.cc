#include "calib/board.h"

#include <charconv>
#include <cmath>
#include <string_view>

namespace fresco::calib {
namespace {

constexpr int kMaxGridSubdivision = 20;   // q: the finest AprilGrid sub-grid we accept
constexpr int kMaxCellsPerSide = 100;     // tags or inner corners per side

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  size_t start = 0;
  for (;;) {
    const size_t end = text.find(separator, start);
    parts.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) return parts;
    start = end + 1;
  }
}

bool ParseWhole(const std::string& text, int* value) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), *value);
  return !text.empty() && r.ec == std::errc() && r.ptr == text.data() + text.size();
}

bool ParseReal(const std::string& text, double* value) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), *value);
  return !text.empty() && r.ec == std::errc() && r.ptr == text.data() + text.size() &&
         std::isfinite(*value);
}

// Smallest q with spacing * q whole (within 1e-6), or 0 when none up to kMaxGridSubdivision.
int GridSubdivision(double spacing) {
  for (int q = 1; q <= kMaxGridSubdivision; ++q)
    if (std::abs(spacing * q - std::round(spacing * q)) < 1e-6) return q;
  return 0;
}

}  // namespace

Status ParseBoardSpec(const std::string& text, const std::string& what, BoardSpec* spec) {
  const std::string usage =
      " (expected chessboard:COLSxROWS:SQUARE_M or aprilgrid:COLSxROWS:TAG_M:SPACING, got '" +
      text + "')";
  const std::vector<std::string> parts = Split(text, ':');
  BoardSpec out;
  out.text = text;
  if (parts[0] == "chessboard") {
    out.kind = BoardKind::kChessboard;
    if (parts.size() != 3) return Status::Error(what + ": chessboard takes 3 fields" + usage);
  } else if (parts[0] == "aprilgrid") {
    out.kind = BoardKind::kAprilGrid;
    if (parts.size() != 4) return Status::Error(what + ": aprilgrid takes 4 fields" + usage);
  } else {
    return Status::Error(what + ": unknown board kind '" + parts[0] + "'" + usage);
  }
  const std::vector<std::string> size = Split(parts[1], 'x');
  if (size.size() != 2 || !ParseWhole(size[0], &out.cols) || !ParseWhole(size[1], &out.rows))
    return Status::Error(what + ": COLSxROWS: '" + parts[1] + "' is not like 9x6" + usage);
  const int min_cells = out.kind == BoardKind::kChessboard ? 2 : 1;
  if (out.cols < min_cells || out.rows < min_cells || out.cols > kMaxCellsPerSide ||
      out.rows > kMaxCellsPerSide)
    return Status::Error(what + ": COLSxROWS: each must be " + std::to_string(min_cells) +
                         ".." + std::to_string(kMaxCellsPerSide) + " (got " + parts[1] + ")");
  const std::string size_name = out.kind == BoardKind::kChessboard ? "SQUARE_M" : "TAG_M";
  if (!ParseReal(parts[2], &out.square_m) || out.square_m <= 0 || out.square_m > 10)
    return Status::Error(what + ": " + size_name + ": must be a length in metres in (0, 10] (got '" +
                         parts[2] + "')");
  if (out.kind == BoardKind::kAprilGrid) {
    if (!ParseReal(parts[3], &out.spacing) || out.spacing <= 0 || out.spacing > 2)
      return Status::Error(what + ": SPACING: must be the gap/tag ratio in (0, 2] (got '" +
                           parts[3] + "')");
    if (GridSubdivision(out.spacing) == 0)
      return Status::Error(what + ": SPACING: " + parts[3] + " is not a multiple of 1/q for q <= " +
                           std::to_string(kMaxGridSubdivision) +
                           " (mrcal needs the corners on a regular grid)");
  }
  *spec = out;
  return Status::Ok();
}

Eigen::Vector3d CornerPosition(const BoardSpec& spec, int id) {
  if (spec.kind == BoardKind::kChessboard)
    return Eigen::Vector3d((id % spec.cols) * spec.square_m, (id / spec.cols) * spec.square_m, 0);
  const int tag = id / 4, k = id % 4;
  const double pitch = spec.TagPitch_m();
  const double x = (tag % spec.cols) * pitch + ((k == 1 || k == 2) ? spec.square_m : 0.0);
  const double y = (tag / spec.cols) * pitch + ((k == 2 || k == 3) ? spec.square_m : 0.0);
  return Eigen::Vector3d(x, y, 0);
}

BoardGrid MakeBoardGrid(const BoardSpec& spec) {
  BoardGrid grid;
  if (spec.kind == BoardKind::kChessboard) {
    grid.width_n = spec.cols;
    grid.height_n = spec.rows;
    grid.spacing_m = spec.square_m;
    for (int id = 0; id < spec.NumCorners(); ++id) grid.grid_index_of_corner.push_back(id);
    return grid;
  }
  const int q = GridSubdivision(spec.spacing);
  const int gap = static_cast<int>(std::lround(spec.spacing * q));
  const int pitch = q + gap;  // grid steps from one tag to the next
  grid.width_n = spec.cols * pitch - gap + 1;
  grid.height_n = spec.rows * pitch - gap + 1;
  grid.spacing_m = spec.square_m / q;
  for (int id = 0; id < spec.NumCorners(); ++id) {
    const int tag = id / 4, k = id % 4;
    const int i = (tag % spec.cols) * pitch + ((k == 1 || k == 2) ? q : 0);
    const int j = (tag / spec.cols) * pitch + ((k == 2 || k == 3) ? q : 0);
    grid.grid_index_of_corner.push_back(j * grid.width_n + i);
  }
  return grid;
}

Eigen::Vector2d PatternSize_m(const BoardSpec& spec) {
  if (spec.kind == BoardKind::kChessboard)
    return Eigen::Vector2d((spec.cols + 1) * spec.square_m, (spec.rows + 1) * spec.square_m);
  return Eigen::Vector2d(spec.cols * spec.TagPitch_m() - spec.spacing * spec.square_m,
                         spec.rows * spec.TagPitch_m() - spec.spacing * spec.square_m);
}

}  // namespace fresco::calib
