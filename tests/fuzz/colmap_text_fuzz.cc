// libFuzzer target: COLMAP's text model. The same bytes go through the cameras.txt,
// images.txt and points3D.txt parsers; accepted cameras are used as the renderer would.
#include <map>
#include <vector>

#include "pipeline/core/poses.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = fresco::fuzz::AsText(data, size);
  std::map<int, fresco::Camera> cameras;
  if (fresco::ParseColmapCameras(text, "/fuzz/cameras.txt", &cameras).ok()) {
    for (const auto& [id, camera] : cameras) fresco::fuzz::ExerciseCamera(camera);
  }
  std::vector<fresco::PosedImage> images;
  if (fresco::ParseColmapImages(text, "/fuzz/images.txt", &images).ok()) {
    for (const fresco::PosedImage& image : images) {
      FUZZ_CHECK(image.cam_from_world.AllFinite());
      FUZZ_CHECK(image.points2d.size() == image.point3d_ids.size());
    }
  }
  std::vector<fresco::Point3D> points;
  if (fresco::ParseColmapPoints(text, "/fuzz/points3D.txt", &points).ok()) {
    for (const fresco::Point3D& point : points) FUZZ_CHECK(point.xyz.allFinite());
  }
  return 0;
}
