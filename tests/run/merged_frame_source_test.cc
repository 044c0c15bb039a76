// Several streams' frames as they arrive (MergedFrameSource): every frame of every stream
// handed out once, with its stream; a stream that delivers at once does not starve one
// that delivers slowly; the first error of any stream ends the run with that error.
#include <chrono>
#include <map>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/run/merged_frame_source.h"

namespace fresco {
namespace {

// `count` frames named 0..count-1, each after `delay`; then the end, or `error`.
class FakeStream : public PosedFrameSource {
 public:
  FakeStream(int count, std::chrono::milliseconds delay, std::string error = "")
      : count_(count), delay_(delay), error_(std::move(error)), origin_{"video", "poses"} {}
  FrameRead Next(SourcedFrame* frame, Status* status) override {
    if (next_ >= count_) {
      if (!error_.empty()) *status = Status::Error(error_);
      return FrameRead::kEnded;
    }
    std::this_thread::sleep_for(delay_);
    frame->posed.frame.index = next_++;
    frame->stream = 0;
    return FrameRead::kFrame;
  }
  int NumStreams() const override { return 1; }
  const FrameOrigin& Origin(int) const override { return origin_; }
  int FrameCount() const override { return count_; }
  std::string EndReason() const override { return "end of fake"; }

 private:
  int count_, next_ = 0;
  std::chrono::milliseconds delay_;
  std::string error_;
  FrameOrigin origin_;
};

std::unique_ptr<MergedFrameSource> Merge(std::unique_ptr<PosedFrameSource> a,
                                         std::unique_ptr<PosedFrameSource> b) {
  std::vector<std::unique_ptr<PosedFrameSource>> streams;
  streams.push_back(std::move(a));
  streams.push_back(std::move(b));
  return std::make_unique<MergedFrameSource>(std::move(streams));
}

TEST(MergedFrameSource, EveryFrameOfEveryStreamOnceInEachStreamsOrder) {
  auto source = Merge(std::make_unique<FakeStream>(30, std::chrono::milliseconds(0)),
                      std::make_unique<FakeStream>(20, std::chrono::milliseconds(1)));
  EXPECT_EQ(source->NumStreams(), 2);
  EXPECT_EQ(source->FrameCount(), 50);
  std::map<int, std::vector<int>> by_stream;
  SourcedFrame frame;
  Status status;
  while (source->Next(&frame, &status) == FrameRead::kFrame)
    by_stream[frame.stream].push_back(frame.posed.frame.index);
  EXPECT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(by_stream[0].size(), 30u);
  ASSERT_EQ(by_stream[1].size(), 20u);
  for (int i = 0; i < 30; ++i) EXPECT_EQ(by_stream[0][i], i);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(by_stream[1][i], i);
  EXPECT_EQ(source->EndReason(), "stream 0: end of fake; stream 1: end of fake");
}

// Stream 0 always has a frame ready, stream 1 one every 5 ms; the painter takes 1 ms a frame.
// Preferring whichever stream is ready first would hand out stream 0's 2,000 frames before
// stream 1's; taken in turn, stream 1's 40 frames (200 ms) all come early, each within a
// few of stream 0's frames of the previous one.
TEST(MergedFrameSource, AStreamThatIsAlwaysReadyDoesNotStarveASlowOne) {
  auto source = Merge(std::make_unique<FakeStream>(2000, std::chrono::milliseconds(0)),
                      std::make_unique<FakeStream>(40, std::chrono::milliseconds(5)));
  SourcedFrame frame;
  Status status;
  int position = 0, last_slow = -1;
  while (source->Next(&frame, &status) == FrameRead::kFrame) {
    if (frame.stream == 1) last_slow = position;
    ++position;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (position > 1000) break;  // stream 1 must be done long before
  }
  EXPECT_GE(last_slow, 39);
  EXPECT_LT(last_slow, 1000) << "the slow stream was starved";
  source->Stop();
}

TEST(MergedFrameSource, TheFirstErrorOfAnyStreamEndsTheRunWithIt) {
  auto source = Merge(std::make_unique<FakeStream>(1000000, std::chrono::milliseconds(1)),
                      std::make_unique<FakeStream>(3, std::chrono::milliseconds(0),
                                                   "b/frames: frame 3 does not decode"));
  SourcedFrame frame;
  Status status;
  int frames = 0;
  while (source->Next(&frame, &status) == FrameRead::kFrame) ++frames;
  EXPECT_EQ(status.message(), "b/frames: frame 3 does not decode");
  EXPECT_LT(frames, 1000);
}

TEST(MergedFrameSource, StopEndsTheRunAndJoinsTheReaders) {
  auto source = Merge(std::make_unique<FakeStream>(1000000, std::chrono::milliseconds(1)),
                      std::make_unique<FakeStream>(1000000, std::chrono::milliseconds(1)));
  SourcedFrame frame;
  Status status;
  ASSERT_EQ(source->Next(&frame, &status), FrameRead::kFrame);
  source->Stop();
  int after = 0;
  while (source->Next(&frame, &status) == FrameRead::kFrame) ++after;
  EXPECT_EQ(after, 0);
  EXPECT_TRUE(status.ok());
  source.reset();  // joins
}

}  // namespace
}  // namespace fresco
