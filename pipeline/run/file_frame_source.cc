#include "pipeline/run/file_frame_source.h"

#include <algorithm>

namespace fresco {

void DecodedFrames::Keep(int stream, int pose_index, cv::Mat bgr) {
  std::lock_guard<std::mutex> lock(mutex_);
  bytes_ += bgr.total() * bgr.elemSize();
  frames_[stream][pose_index] = std::move(bgr);
}

bool DecodedFrames::Has(int stream, int pose_index) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_[stream].count(pose_index) > 0;
}

cv::Mat DecodedFrames::Take(int stream, int pose_index) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto found = frames_[stream].find(pose_index);
  if (found == frames_[stream].end()) return cv::Mat();
  cv::Mat bgr = std::move(found->second);
  frames_[stream].erase(found);
  bytes_ -= bgr.total() * bgr.elemSize();
  return bgr;
}

size_t DecodedFrames::bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bytes_;
}

void DecodedFrames::KeepDepth(int stream, int pose_index, cv::Mat depth,
                              const Rigid3d& cam_from_local) {
  std::lock_guard<std::mutex> lock(mutex_);
  depths_[stream][pose_index] = {std::move(depth), cam_from_local};
}

bool DecodedFrames::TakeDepth(int stream, int pose_index, cv::Mat* depth, Rigid3d* cam_from_local) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto found = depths_[stream].find(pose_index);
  if (found == depths_[stream].end()) return false;
  *depth = std::move(found->second.first);
  *cam_from_local = found->second.second;
  depths_[stream].erase(found);
  return true;
}

FileFrameSource::FileFrameSource(const Project& project, const std::vector<const Capture*>& streams,
                                 SkipFrame skip, bool read_frames_without_pose,
                                 std::shared_ptr<DecodedFrames> decoded)
    : streams_(streams),
      skip_(std::move(skip)),
      decoded_(std::move(decoded)),
      ended_(streams.size(), false),
      read_(streams.size(), 0) {
  const std::vector<StreamSpec> specs = project.Streams();
  for (size_t s = 0; s < streams_.size(); ++s) {
    origins_.push_back({project.Resolve(specs[s].video), project.Resolve(specs[s].poses)});
    std::function<bool(const Frame&)> skip_frame;
    if (skip_ || decoded_ || !read_frames_without_pose)
      skip_frame = [this, s, read_frames_without_pose](const Frame& header) {
        SourcedFrame f;
        f.posed.frame = header;
        f.stream = static_cast<int>(s);
        MatchPose(static_cast<int>(s), &f);
        if (!f.posed.has_pose) return !read_frames_without_pose;
        if (f.camera && skip_ && skip_(f)) return true;
        return decoded_ && decoded_->Has(f.stream, f.pose_index);  // Next() takes it
      };
    skip_frame_.push_back(skip_frame);
    readers_.emplace_back();
    StartReading(s);
    fps_.push_back(specs[s].fps);
  }
  if (std::any_of(fps_.begin(), fps_.end(), [](double fps) { return !(fps > 0); })) fps_.clear();
}

void FileFrameSource::StartReading(size_t s) {
  readers_[s].reset();  // waits for the frame it was reading ahead
  readers_[s] = std::make_unique<ReadAhead>(streams_[s]->video.get(), skip_frame_[s]);
}

bool FileFrameSource::Tell(SourcePosition* position) const {
  position->read = read_;
  position->ended = ended_;
  position->next = next_;
  return true;
}

Status FileFrameSource::Seek(const SourcePosition& position) {
  if (position.read.size() != streams_.size() || position.ended.size() != streams_.size())
    return Status::Error("seek: a position of " + std::to_string(position.read.size()) +
                         " streams in a source of " + std::to_string(streams_.size()));
  for (size_t s = 0; s < streams_.size(); ++s) {
    readers_[s].reset();  // nothing reads the video while it moves
    if (!streams_[s]->video->Seek(static_cast<int>(position.read[s])))
      return Status::Error(origins_[s].video + ": cannot go back to frame " +
                           std::to_string(position.read[s]));
    StartReading(s);
  }
  read_ = position.read;
  ended_ = position.ended;
  next_ = position.next;
  return Status::Ok();
}

int FileFrameSource::PickStream() {
  const int n = static_cast<int>(streams_.size());
  int best = -1;
  for (int k = 0; k < n; ++k) {
    const int s = fps_.empty() ? (next_ + k) % n : k;
    if (ended_[s]) continue;
    if (fps_.empty()) {
      next_ = (s + 1) % n;
      return s;
    }
    // Next frame times read/fps compared without division: equal times stay equal.
    if (best < 0 || read_[s] * fps_[best] < read_[best] * fps_[s]) best = s;
  }
  return best;
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
  for (int s = PickStream(); s >= 0; s = PickStream()) {
    if (!readers_[s]->Next(&frame->posed.frame, status, &frame->skipped)) {
      if (!status->ok()) return FrameRead::kEnded;
      ended_[s] = true;
      continue;
    }
    ++read_[s];
    frame->stream = s;
    MatchPose(s, frame);
    if (!frame->posed.has_pose) frame->skipped = false;  // not decoded: a frame without a pose
    frame->posed.frame.depth.release();
    if (decoded_ && frame->posed.has_pose)
      decoded_->TakeDepth(s, frame->pose_index, &frame->posed.frame.depth,
                          &frame->posed.frame.depth_cam_from_local);
    // Passed over because it was decoded before (unless `skip` passes it over too).
    if (frame->skipped && decoded_ && frame->posed.has_pose)
      if (cv::Mat bgr = decoded_->Take(s, frame->pose_index);
          !bgr.empty() && !(frame->camera && skip_ && skip_(*frame))) {
        frame->posed.frame.bgr = std::move(bgr);
        frame->skipped = false;
      }
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
  frame->posed.frame.movers.release();
  if (!pose) return;
  frame->posed.cam_from_world = pose->cam_from_world;
  frame->camera = capture.CameraFor(*pose);
  frame->camera_id = pose->camera_id;
  frame->pose_name = pose->name;
  frame->pose_index = static_cast<int>(pose - capture.poses.data());
  if (frame->pose_index < static_cast<int>(capture.movers.size()))
    frame->posed.frame.movers = capture.movers[frame->pose_index];
}

}  // namespace fresco
