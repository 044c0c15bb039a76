// mrcal `.cameramodel` files, read and written through libmrcal (mrcal's own tools read
// what we write). Only the lens models Camera supports are accepted (PINHOLE, OPENCV4/5/8);
// other mrcal models give a clear error. The writer keeps full precision (mrcal's C writer
// rounds to 6 decimals, so we write the Python-dict text format ourselves and check it
// with mrcal's reader).
#pragma once

#include <map>
#include <string>

#include "pipeline/core/camera.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace fresco {

struct CameraModelFile {
  Camera camera;
  Rigid3d cam_from_ref;  // mrcal's extrinsics (rt_cam_ref)
};

Status ReadCameraModel(const std::string& path, CameraModelFile* model);
Status ParseCameraModel(const std::string& text, const std::string& name, CameraModelFile* model);
Status WriteCameraModel(const std::string& path, const CameraModelFile& model);

// Reads a camera from either a `.cameramodel` or a COLMAP `cameras.txt` (all cameras, by
// CAMERA_ID; a .cameramodel yields camera id 1).
Status ReadCameras(const std::string& path, std::map<int, Camera>* cameras);

}  // namespace fresco
