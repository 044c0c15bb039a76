#include "pipeline/paint/open_project.h"

namespace fresco {

Status OpenPaintSession(const Project& project, Capture* capture,
                        std::unique_ptr<PaintSession>* session) {
  return OpenPaintSession(project, CaptureLoadOptions(), capture, session);
}

Status OpenPaintSession(const Project& project, const CaptureLoadOptions& load_options,
                        Capture* capture, std::unique_ptr<PaintSession>* session) {
  FRESCO_RETURN_IF_ERROR(LoadCapture(project, load_options, capture));
  if (capture->cameras.empty())
    return Status::Error(project.Resolve(project.camera) + ": no camera");
  PaintSessionInputs inputs;
  inputs.scene = &capture->scene;
  inputs.pipeline = project.pipeline;
  inputs.grouping = project.grouping;
  inputs.typical_camera = &capture->cameras.begin()->second;
  for (const PosedImage& p : capture->poses) inputs.expected_poses.push_back(p.cam_from_world);
  if (Status s = PaintSession::Create(inputs, session); !s.ok())
    return Status::Error(project.file_path + ": " + s.message());
  return Status::Ok();
}

}  // namespace fresco
