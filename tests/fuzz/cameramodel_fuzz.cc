// libFuzzer target: mrcal `.cameramodel` text (ParseCameraModel: our diagnosis, then
// libmrcal's reader); an accepted camera is used as the renderer would.
#include "pipeline/core/cameramodel_io.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fresco::CameraModelFile model;
  if (!fresco::ParseCameraModel(fresco::fuzz::AsText(data, size), "/fuzz/camera.cameramodel",
                                &model)
           .ok()) {
    return 0;
  }
  FUZZ_CHECK(model.cam_from_ref.AllFinite());
  fresco::fuzz::ExerciseCamera(model.camera);
  return 0;
}
