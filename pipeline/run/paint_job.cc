#include "pipeline/run/paint_job.h"

#include "pipeline/paint/open_project.h"
#include "pipeline/run/file_frame_source.h"
#include "pipeline/run/live_frame_source.h"

namespace fresco {

Status OpenPaintJob(const Project& project, const PaintJobOptions& options,
                    std::unique_ptr<PaintJob>* job) {
  if (!options.one_stream_for.empty())
    FRESCO_RETURN_IF_ERROR(CheckOneStream(project, options.one_stream_for));
  auto result = std::make_unique<PaintJob>();
  result->live = IsLiveProject(project);
  const std::vector<StreamSpec> specs = project.Streams();
  if (result->live && specs.size() > 1) {
    return Status::Error(project.file_path + ": streams: live sources need a project with " +
                         "one stream (this one has " + std::to_string(specs.size()) + ")");
  }
  CaptureLoadOptions load_options;
  load_options.open_video = !result->live;  // a live video opens after the pose feed connects
  FRESCO_RETURN_IF_ERROR(
      OpenPaintSession(project, load_options, &result->captures, &result->session));
  // Each camera's ray table and the mesh's culling clusters are set-up, not painting: built
  // here, the first frame costs what the others do (a few photos of a large mesh would
  // otherwise show a painting rate set by the first frame).
  for (const Capture& capture : result->captures)
    for (const auto& [id, camera] : capture.cameras) result->session->PrepareCamera(camera);
  if (result->live) {
    PaintJob& j = *result;
    FRESCO_RETURN_IF_ERROR(OpenLiveInputs(project.ForStream(0), j.captures[0], *j.session,
                                          options.keep_tracker_poses, &j.live_inputs));
    j.source = std::make_unique<LiveFrameSource>(
        &j.live_inputs,
        FrameOrigin{project.Resolve(specs[0].video), project.Resolve(specs[0].poses)});
  } else {
    std::vector<const Capture*> streams;
    for (const Capture& capture : result->captures) streams.push_back(&capture);
    result->source = std::make_unique<FileFrameSource>(project, streams);
  }
  *job = std::move(result);
  return Status::Ok();
}

}  // namespace fresco
