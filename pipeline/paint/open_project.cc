#include "pipeline/paint/open_project.h"

#include <algorithm>

namespace fresco {
namespace {

// The session over the scene of streams[0], its texel size chosen for every stream.
Status CreateSession(const Project& project, const std::vector<const Capture*>& streams,
                     const BufferLayout* layout, bool layout_only,
                     std::unique_ptr<PaintSession>* session) {
  const std::vector<StreamSpec> specs = project.Streams();
  for (size_t i = 0; i < streams.size(); ++i) {
    if (streams[i]->cameras.empty())
      return Status::Error(project.Resolve(specs[i].camera) + ": no camera");
  }
  PaintSessionInputs inputs;
  inputs.scene = &streams[0]->scene;
  inputs.pipeline = project.pipeline;
  inputs.grouping = project.grouping;
  inputs.layout = layout;
  inputs.layout_only = layout_only;
  const auto expected_poses = [](const Capture& capture) {
    std::vector<Rigid3d> poses;
    for (const PosedImage& p : capture.poses) poses.push_back(p.cam_from_world);
    return poses;
  };
  if (streams.size() == 1) {
    inputs.typical_camera = &streams[0]->cameras.begin()->second;
    inputs.expected_poses = expected_poses(*streams[0]);
  } else if (inputs.pipeline.texel_size_m <= 0 && !layout) {  // a layout holds its own
    double texel_size_m = 0;
    for (const Capture* stream : streams) {
      const double t = AutomaticTexelSize(*inputs.scene, stream->cameras.begin()->second,
                                          expected_poses(*stream));
      texel_size_m = texel_size_m > 0 ? std::min(texel_size_m, t) : t;
    }
    inputs.pipeline.texel_size_m = texel_size_m;
  }
  if (Status s = PaintSession::Create(inputs, session); !s.ok())
    return Status::Error(project.file_path + ": " + s.message());
  return Status::Ok();
}

}  // namespace

Status OpenPaintSession(const Project& project, Capture* capture,
                        std::unique_ptr<PaintSession>* session) {
  return OpenPaintSession(project, CaptureLoadOptions(), capture, session);
}

Status OpenPaintSession(const Project& project, const CaptureLoadOptions& load_options,
                        Capture* capture, std::unique_ptr<PaintSession>* session) {
  FRESCO_RETURN_IF_ERROR(LoadCapture(project, load_options, capture));
  return CreateSession(project, {capture}, nullptr, false, session);
}

Status OpenPaintSession(const Project& project, const CaptureLoadOptions& load_options,
                        std::vector<Capture>* streams, std::unique_ptr<PaintSession>* session) {
  FRESCO_RETURN_IF_ERROR(LoadStreamCaptures(project, load_options, streams));
  return CreatePaintSession(project, *streams, nullptr, session);
}

Status CreatePaintSession(const Project& project, const std::vector<Capture>& streams,
                          const BufferLayout* layout, std::unique_ptr<PaintSession>* session,
                          bool layout_only) {
  std::vector<const Capture*> views;
  for (const Capture& stream : streams) views.push_back(&stream);
  return CreateSession(project, views, layout, layout_only, session);
}

}  // namespace fresco
