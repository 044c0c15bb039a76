#include "pipeline/run/merged_frame_source.h"

#include <algorithm>
#include <chrono>

namespace fresco {

MergedFrameSource::MergedFrameSource(std::vector<std::unique_ptr<PosedFrameSource>> streams,
                                     int poll_ms)
    : streams_(std::move(streams)), slots_(streams_.size()), poll_ms_(poll_ms) {
  strict_turns_ = std::none_of(streams_.begin(), streams_.end(),
                               [](const auto& stream) { return stream->RealTime(); });
  for (size_t s = 0; s < streams_.size(); ++s)
    pumps_.emplace_back([this, s] { Pump(static_cast<int>(s)); });
}

MergedFrameSource::~MergedFrameSource() {
  Stop();
  for (std::thread& pump : pumps_) pump.join();
}

void MergedFrameSource::Pump(int stream) {
  PosedFrameSource& source = *streams_[stream];
  Slot& slot = slots_[stream];
  for (;;) {
    SourcedFrame frame;
    Status status;
    FrameRead read = source.Next(&frame, &status);
    std::unique_lock<std::mutex> lock(mutex_);
    if (read == FrameRead::kWaiting && !stopping_) continue;  // a polled source: ask again
    if (read != FrameRead::kFrame || stopping_) {
      slot.ended = true;
      slot.status = status;
      changed_.notify_all();
      return;
    }
    frame.stream = stream;
    slot.frame = std::move(frame);
    slot.full = true;
    changed_.notify_all();
    // The next frame is read once this one is taken: meanwhile a live stream's own queue
    // holds (and drops) what arrives.
    changed_.wait(lock, [&] { return !slot.full || stopping_; });
    if (stopping_) {
      slot.ended = true;
      changed_.notify_all();
      return;
    }
  }
}

FrameRead MergedFrameSource::Next(SourcedFrame* frame, Status* status) {
  std::unique_lock<std::mutex> lock(mutex_);
  const int n = static_cast<int>(slots_.size());
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(poll_ms_);
  for (;;) {
    if (stopping_) return FrameRead::kEnded;
    bool all_ended = true;
    for (int k = 0; k < n; ++k) {
      Slot& slot = slots_[(next_ + k) % n];
      if (slot.ended && !slot.status.ok() && !slot.full) {
        *status = slot.status;
        return FrameRead::kEnded;
      }
    }
    for (int k = 0; k < n; ++k) {
      const int s = (next_ + k) % n;
      Slot& slot = slots_[s];
      if (slot.full) {
        *frame = std::move(slot.frame);
        slot.full = false;
        next_ = (s + 1) % n;
        changed_.notify_all();
        return FrameRead::kFrame;
      }
      all_ended = all_ended && slot.ended;
      if (strict_turns_ && !slot.ended) break;  // its turn: wait for it
    }
    if (all_ended) return FrameRead::kEnded;
    if (poll_ms_ < 0)
      changed_.wait(lock);
    else if (changed_.wait_until(lock, deadline) == std::cv_status::timeout)
      return FrameRead::kWaiting;
  }
}

int MergedFrameSource::FrameCount() const {
  int total = 0;
  for (const auto& stream : streams_) {
    const int count = stream->FrameCount();
    if (count < 0) return -1;
    total += count;
  }
  return total;
}

std::string MergedFrameSource::EndReason() const {
  if (streams_.size() == 1) return streams_[0]->EndReason();
  std::string reason;
  for (size_t s = 0; s < streams_.size(); ++s) {
    if (!reason.empty()) reason += "; ";
    reason += "stream " + std::to_string(s) + ": " + streams_[s]->EndReason();
  }
  return reason;
}

void MergedFrameSource::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  for (const auto& stream : streams_) stream->Stop();
}

std::unique_ptr<PosedFrameSource> JoinStreamSources(
    std::vector<std::unique_ptr<PosedFrameSource>> sources, int poll_ms) {
  if (sources.size() == 1 && poll_ms < 0) return std::move(sources[0]);
  return std::make_unique<MergedFrameSource>(std::move(sources), poll_ms);
}

}  // namespace fresco
