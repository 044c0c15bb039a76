// libFuzzer target: calibration board specs (`--board chessboard:9x6:0.025`,
// `aprilgrid:6x6:0.088:0.3`); an accepted board's corners must land inside mrcal's grid.
#include "calib/board.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fresco::calib::BoardSpec spec;
  if (!fresco::calib::ParseBoardSpec(fresco::fuzz::AsText(data, size), "--board", &spec).ok()) {
    return 0;
  }
  const fresco::calib::BoardGrid grid = fresco::calib::MakeBoardGrid(spec);
  FUZZ_CHECK(grid.width_n > 0 && grid.height_n > 0 && grid.spacing_m > 0);
  FUZZ_CHECK(static_cast<int>(grid.grid_index_of_corner.size()) == spec.NumCorners());
  for (int id = 0; id < spec.NumCorners(); ++id) {
    const int index = grid.grid_index_of_corner[id];
    FUZZ_CHECK(index >= 0 && index < grid.width_n * grid.height_n);
    FUZZ_CHECK(fresco::calib::CornerPosition(spec, id).allFinite());
  }
  FUZZ_CHECK(fresco::calib::PatternSize_m(spec).allFinite());
  return 0;
}
