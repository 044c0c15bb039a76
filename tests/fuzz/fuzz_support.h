// Shared by the libFuzzer targets of tests/fuzz: the input as text, a check that aborts
// (libFuzzer then saves the input as a crash), and what every caller does with a camera a
// parser accepted (project and unproject across the image), so a camera that passes
// validation but breaks the lens code is found too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <Eigen/Core>

#include "pipeline/core/camera.h"

#define FUZZ_CHECK(condition)                                                          \
  do {                                                                                 \
    if (!(condition)) {                                                                \
      std::fprintf(stderr, "%s:%d: FUZZ_CHECK failed: %s\n", __FILE__, __LINE__, #condition); \
      std::abort();                                                                    \
    }                                                                                  \
  } while (0)

namespace fresco::fuzz {

inline std::string AsText(const uint8_t* data, size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

// Projects and unprojects a few points and pixels; a pixel that unprojects must project
// back near where it came from.
inline void ExerciseCamera(const Camera& camera) {
  FUZZ_CHECK(camera.width > 0 && camera.height > 0);
  for (int i = 0; i <= 2; ++i) {
    for (int j = 0; j <= 2; ++j) {
      const Eigen::Vector2d pixel(0.5 * i * (camera.width - 1), 0.5 * j * (camera.height - 1));
      Eigen::Vector2d normalized;
      if (!camera.Unproject(pixel, &normalized)) continue;
      FUZZ_CHECK(normalized.allFinite());
      Eigen::Vector2d back;
      if (camera.Project(Eigen::Vector3d(normalized.x(), normalized.y(), 1.0), &back)) {
        FUZZ_CHECK(back.allFinite());
      }
    }
  }
  Eigen::Vector2d pixel;
  Eigen::Matrix<double, 2, 3> jacobian;
  for (const Eigen::Vector3d& point : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, -2, 0.5),
                                       Eigen::Vector3d(1e6, 1e6, 1e-6)}) {
    if (camera.ProjectWithJacobian(point, &pixel, &jacobian)) FUZZ_CHECK(pixel.allFinite());
  }
}

}  // namespace fresco::fuzz
