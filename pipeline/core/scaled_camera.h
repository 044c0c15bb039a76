// A camera seen through an image resized to width x height: focal lengths and principal point
// scale with the pixels ((0,0) stays the centre of the top-left pixel); the lens's distortion,
// in normalized coordinates, stays as it is.
#pragma once

#include "pipeline/core/camera.h"

namespace fresco {

inline Camera ScaledCamera(const Camera& camera, int width, int height) {
  Camera scaled = camera;
  const double sx = static_cast<double>(width) / camera.width;
  const double sy = static_cast<double>(height) / camera.height;
  scaled.width = width, scaled.height = height;
  scaled.fx *= sx, scaled.fy *= sy;
  scaled.cx = (camera.cx + 0.5) * sx - 0.5, scaled.cy = (camera.cy + 0.5) * sy - 0.5;
  return scaled;
}

}  // namespace fresco
