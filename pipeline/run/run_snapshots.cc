#include "pipeline/run/run_snapshots.h"

#include <algorithm>

namespace fresco {

RunSnapshots::RunSnapshots(int every, size_t budget_bytes)
    : every_(std::max(1, every)), budget_bytes_(budget_bytes) {}

bool RunSnapshots::Due(int frames_read) const {
  if (frames_read % every_ != 0 || states_.count(frames_read) != 0) return false;
  return last_offered_bytes_ <= budget_bytes_;
}

void RunSnapshots::DoubleTheSpacing() {
  every_ *= 2;
  for (auto it = states_.begin(); it != states_.end();)
    if (it->first % every_ != 0) {
      bytes_ -= it->second.bytes();
      it = states_.erase(it);
    } else {
      ++it;
    }
}

void RunSnapshots::Add(int frames_read, PaintRunState state) {
  const size_t bytes = state.bytes();
  last_offered_bytes_ = bytes;
  if (bytes > budget_bytes_) return;  // one state alone over the budget: none kept
  // Thinned until the new state fits: the spacing doubles, every state off it dropped.
  while (bytes_ + bytes > budget_bytes_ && states_.size() > 1) DoubleTheSpacing();
  // Room for one state only: the newest on the spacing replaces the one kept (the first too),
  // the spacing doubling each time (saves stay few); a step back then paints at most the
  // frames since the state kept, not every frame from the first.
  if (bytes_ + bytes > budget_bytes_) {
    bytes_ = 0;
    states_.clear();
    every_ *= 2;
  }
  if (frames_read % every_ != 0) return;
  bytes_ += bytes;
  states_[frames_read] = std::move(state);
}

const PaintRunState* RunSnapshots::AtOrBefore(int frames_read, int* its_frames_read) const {
  auto it = states_.upper_bound(frames_read);
  if (it == states_.begin()) return nullptr;
  --it;
  *its_frames_read = it->first;
  return &it->second;
}

}  // namespace fresco
