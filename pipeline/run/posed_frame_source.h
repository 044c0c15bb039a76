// Where a paint run's frames come from: a source hands out frames one at a time, each with
// its pose and camera when it has them. Sources read; they do not judge: what a frame
// without a pose, with an unknown camera or of the wrong size means is decided once, by
// the frame policy (frame_policy.h), for every source and every client (`fresco run`,
// `fresco bench`, the app).
//
// Sources: FileFrameSource (file_frame_source.h: folders or video files with poses files,
// several streams interleaved, read ahead on threads) and LiveFrameSource
// (live_frame_source.h: a live video with a pose feed or a TUM file, matched by time).
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/camera.h"
#include "pipeline/core/status.h"
#include "pipeline/live/live_frames.h"

namespace fresco {

// One frame as a source gives it.
struct SourcedFrame {
  PosedFrame posed;                // the frame, and its pose (cam_from_world) when it has one
  const Camera* camera = nullptr;  // the pose's camera; null without a pose or when unknown
  int camera_id = -1;              // the pose's CAMERA_ID (-1: the stream's only camera)
  std::string pose_name;           // the pose's image name as the poses file lists it
  int pose_index = -1;             // index into the stream's Capture::poses (file sources)
  int stream = 0;                  // index into Project::Streams()
  // Passed over unread (no pixels): a shard's source skips the frames whose view meets none
  // of its buffers (FileFrameSource's `skip`).
  bool skipped = false;
};

// The files (or addresses) one stream's frames and poses come from, as messages name them.
struct FrameOrigin {
  std::string video;
  std::string poses;
};

enum class FrameRead {
  kFrame,    // a frame was handed out
  kWaiting,  // none yet (a live source polled with a short wait); ask again
  kEnded,    // the end of every stream, or an error (then in `status`)
};

// Where a source of files is in its streams (PosedFrameSource::Tell), to go back to (Seek).
struct SourcePosition {
  std::vector<long long> read;  // per stream: frames handed out
  std::vector<bool> ended;      // per stream: at its end
  int next = 0;                 // the stream whose turn is next
};

class PosedFrameSource {
 public:
  virtual ~PosedFrameSource() = default;
  // The next frame. kEnded with `status` set: a frame that does not decode, a truncated
  // video, a pose feed that failed (errors name the file or address).
  virtual FrameRead Next(SourcedFrame* frame, Status* status) = 0;
  virtual int NumStreams() const = 0;
  virtual const FrameOrigin& Origin(int stream) const = 0;
  // Frames of all streams when known up front, else -1.
  virtual int FrameCount() const { return -1; }
  // Why the source ended without an error, for status lines ("end of video").
  virtual std::string EndReason() const { return "end of video"; }
  // Stops reading (threads, live captures); Next then ends.
  virtual void Stop() {}
  // Frames arrive on a camera's or a stream's clock (and are dropped when the painter is
  // behind); false for files and folders, live pose feeds or not: a replay.
  virtual bool RealTime() const { return false; }
  // Sources of files: where the next frame comes from; false where a source cannot go back.
  virtual bool Tell(SourcePosition* /*position*/) const { return false; }
  // Goes back (or on) to where Tell was: the frames from there are read again, as they were.
  virtual Status Seek(const SourcePosition& /*position*/) {
    return Status::Error("this source of frames cannot go back (live)");
  }
};

}  // namespace fresco
