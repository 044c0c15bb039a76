// Posed frames from files: each stream's video (a folder of images or a video file) with
// its poses file (COLMAP images.txt matched by name, TUM matched in order). Several streams
// are interleaved in time order when every stream gives its `fps` (frame i at i / fps; at
// equal times the stream listed first), else by frame index: frame 0 of each stream, then
// frame 1 of each, ... (what cameras recording the same period at the same rate give); a
// stream that ends leaves the others going on. Each stream is read one frame ahead on its own
// thread (read_ahead.h).
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/capture.h"
#include "pipeline/core/project.h"
#include "pipeline/run/posed_frame_source.h"
#include "pipeline/run/read_ahead.h"

namespace fresco {

// Frames already decoded (the whole-capture pre-pass keeps them: paint_job.h), each handed out
// once instead of decoded again; by stream and pose index. Safe to read from the reading
// threads while the painting thread takes.
class DecodedFrames {
 public:
  explicit DecodedFrames(size_t streams) : frames_(streams), depths_(streams) {}
  void Keep(int stream, int pose_index, cv::Mat bgr);
  bool Has(int stream, int pose_index) const;
  cv::Mat Take(int stream, int pose_index);  // empty when not kept (or taken)
  size_t bytes() const;
  // The mesh's depth from the frame's camera at `cam_from_local` (Frame::depth), each handed
  // out once, with the frame however it is read.
  void KeepDepth(int stream, int pose_index, cv::Mat depth, const Rigid3d& cam_from_local);
  bool TakeDepth(int stream, int pose_index, cv::Mat* depth, Rigid3d* cam_from_local);

 private:
  mutable std::mutex mutex_;
  std::vector<std::map<int, cv::Mat>> frames_;
  std::vector<std::map<int, std::pair<cv::Mat, Rigid3d>>> depths_;
  size_t bytes_ = 0;
};

class FileFrameSource : public PosedFrameSource {
 public:
  // `streams[i]`: stream i of `project` (Project::Streams() order) loaded with its video
  // open (LoadCapture); each must outlive the source.
  // `skip` (optional; folders and video files, VideoSource::PeekNext): asked, on
  // the reading thread, with a posed frame's header (pose, camera; no pixels); true: the frame
  // is not read and comes out with `skipped` set.
  // `read_frames_without_pose` false (folders and video files): a frame without a pose is not
  // decoded (a video file's: not converted) and
  // comes out without pixels (nothing paints it; the app shows it, so reads it).
  // `decoded` (optional; folders only): a frame kept there is taken from it, not decoded.
  using SkipFrame = std::function<bool(const SourcedFrame& header)>;
  FileFrameSource(const Project& project, const std::vector<const Capture*>& streams,
                  SkipFrame skip = nullptr, bool read_frames_without_pose = true,
                  std::shared_ptr<DecodedFrames> decoded = nullptr);

  FrameRead Next(SourcedFrame* frame, Status* status) override;
  int NumStreams() const override { return static_cast<int>(streams_.size()); }
  const FrameOrigin& Origin(int stream) const override { return origins_[stream]; }
  int FrameCount() const override;
  bool Tell(SourcePosition* position) const override;
  Status Seek(const SourcePosition& position) override;

 private:
  // Fills the pose, camera and its identity of a frame of stream `s`.
  void MatchPose(int s, SourcedFrame* frame) const;
  void StartReading(size_t s);  // stream s's reader, from where its video stands
  // The stream to read from next (time order or in turn), -1 when every stream ended.
  int PickStream();

  std::vector<const Capture*> streams_;
  SkipFrame skip_;
  std::shared_ptr<DecodedFrames> decoded_;
  std::vector<FrameOrigin> origins_;
  std::vector<std::function<bool(const Frame&)>> skip_frame_;  // per stream, for its reader
  std::vector<std::unique_ptr<ReadAhead>> readers_;
  std::vector<bool> ended_;
  std::vector<double> fps_;      // per stream, when every stream has one (else empty)
  std::vector<long long> read_;  // frames read per stream
  int next_ = 0;                 // in turn: the stream to read from next
};

}  // namespace fresco
