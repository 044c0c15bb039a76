// Several streams' frames as they arrive: what a project with live streams paints from (one
// live camera and one file stream, or several live cameras). Each stream has its own source
// (a LiveFrameSource or a one-stream FileFrameSource) read on its own thread into a slot
// that holds one frame; Next hands out a waiting frame, taking the streams in turn among
// those that have one, so a stream that delivers often cannot starve a slower one. When no
// stream is real time (files and folders, replayed with or without live pose feeds), the
// turns are strict: Next waits for the stream whose turn it is (unless it ended), so a replay
// paints its frames in the same order on every run and in every client. While a
// stream's frame waits in its slot, its live queue goes on filling (and drops its oldest
// frames when the painter is slower than the camera: live_frames.h), so every stream is
// painted at its share of the painter's rate.
//
// The run ends when every stream has ended, or at the first error of any stream (a frame
// that does not decode, a pose feed that failed): the error names the stream's file or
// address as the stream's own source names it.
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/run/posed_frame_source.h"

namespace fresco {

class MergedFrameSource : public PosedFrameSource {
 public:
  // `streams[i]`: stream i's own source (it reports its frames as stream 0). `poll_ms` >= 0:
  // Next waits at most that long for a frame and then says kWaiting (the app's worker,
  // which has commands to answer meanwhile); < 0: Next waits for a frame or the end.
  explicit MergedFrameSource(std::vector<std::unique_ptr<PosedFrameSource>> streams,
                             int poll_ms = -1);
  ~MergedFrameSource() override;
  MergedFrameSource(const MergedFrameSource&) = delete;
  MergedFrameSource& operator=(const MergedFrameSource&) = delete;

  FrameRead Next(SourcedFrame* frame, Status* status) override;
  int NumStreams() const override { return static_cast<int>(streams_.size()); }
  const FrameOrigin& Origin(int stream) const override { return streams_[stream]->Origin(0); }
  int FrameCount() const override;
  // Each stream's end ("stream 1: live video ended: ..."), "; "-separated; one stream's as
  // it says it.
  std::string EndReason() const override;
  void Stop() override;

 private:
  struct Slot {
    SourcedFrame frame;
    bool full = false;
    bool ended = false;
    Status status;  // the stream's error, when it ended with one
  };
  void Pump(int stream);

  std::vector<std::unique_ptr<PosedFrameSource>> streams_;
  std::vector<Slot> slots_;
  std::vector<std::thread> pumps_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  bool stopping_ = false;
  int next_ = 0;  // the stream to look at first
  int poll_ms_ = -1;
  bool strict_turns_ = false;  // no stream is real time
};

// The source of a run over several streams: `sources[i]` is stream i's own source. One
// source is returned as it is unless it is to be polled (`poll_ms` >= 0: read on its own
// thread, as several are); several are merged (MergedFrameSource, with `poll_ms`).
std::unique_ptr<PosedFrameSource> JoinStreamSources(
    std::vector<std::unique_ptr<PosedFrameSource>> sources, int poll_ms = -1);

}  // namespace fresco
