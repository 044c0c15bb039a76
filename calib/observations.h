// What the solver consumes: the corners seen in each image (one "view" per image).
#pragma once

#include <string>
#include <vector>

#include "calib/detect.h"

namespace fresco::calib {

struct BoardView {
  std::string name;                        // image file name (for reports)
  std::vector<CornerObservation> corners;  // ids unique within the view
};

}  // namespace fresco::calib
