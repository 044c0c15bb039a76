#include "pipeline/run/file_frame_source.h"

namespace fresco {

FileFrameSource::FileFrameSource(const Project& project, const std::vector<const Capture*>& streams)
    : streams_(streams), ended_(streams.size(), false) {
  const std::vector<StreamSpec> specs = project.Streams();
  for (size_t s = 0; s < streams_.size(); ++s) {
    origins_.push_back({project.Resolve(specs[s].video), project.Resolve(specs[s].poses)});
    readers_.push_back(std::make_unique<ReadAhead>(streams_[s]->video.get()));
  }
}

int FileFrameSource::FrameCount() const {
  int total = 0;
  for (const Capture* stream : streams_) {
    const int count = stream->video->FrameCount();
    if (count < 0) return -1;
    total += count;
  }
  return total;
}

FrameRead FileFrameSource::Next(SourcedFrame* frame, Status* status) {
  for (size_t tried = 0; tried < streams_.size(); ++tried) {
    const int s = next_;
    next_ = (next_ + 1) % static_cast<int>(streams_.size());
    if (ended_[s]) continue;
    if (!readers_[s]->Next(&frame->posed.frame, status)) {
      if (!status->ok()) return FrameRead::kEnded;
      ended_[s] = true;
      continue;
    }
    frame->stream = s;
    MatchPose(s, frame);
    return FrameRead::kFrame;
  }
  return FrameRead::kEnded;  // every stream ended
}

void FileFrameSource::MatchPose(int s, SourcedFrame* frame) const {
  const Capture& capture = *streams_[s];
  const PosedImage* pose = capture.PoseForFrame(frame->posed.frame);
  frame->posed.has_pose = pose != nullptr;
  frame->camera = nullptr;
  frame->camera_id = -1;
  frame->pose_name.clear();
  frame->pose_index = -1;
  if (!pose) return;
  frame->posed.cam_from_world = pose->cam_from_world;
  frame->camera = capture.CameraFor(*pose);
  frame->camera_id = pose->camera_id;
  frame->pose_name = pose->name;
  frame->pose_index = static_cast<int>(pose - capture.poses.data());
}

}  // namespace fresco
