// libFuzzer target: TUM trajectories (ParseTumTrajectory); accepted poses are finite rigid
// transforms.
#include <cmath>
#include <vector>

#include "pipeline/core/poses.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<fresco::PosedImage> poses;
  if (!fresco::ParseTumTrajectory(fresco::fuzz::AsText(data, size), "/fuzz/trajectory.tum", &poses)
           .ok()) {
    return 0;
  }
  for (const fresco::PosedImage& pose : poses) {
    FUZZ_CHECK(pose.cam_from_world.AllFinite());
    FUZZ_CHECK(std::isfinite(pose.timestamp_s));
    FUZZ_CHECK(std::abs(pose.cam_from_world.rotation.norm() - 1.0) < 1e-9);
  }
  return 0;
}
