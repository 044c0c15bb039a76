#include "pipeline/run/run_snapshots.h"

#include <algorithm>
#include <unordered_set>

#include "pipeline/paint/painting_state.h"

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
    it = it->first % every_ != 0 ? states_.erase(it) : std::next(it);
}

size_t RunSnapshots::HeldBytes(const PaintRunState* adding) const {
  std::unordered_set<const void*> blocks;
  size_t bytes = 0;
  auto count = [&](const PaintRunState& state) {
    if (!state.painting) return;
    bytes += state.painting->bytes - state.painting->block_bytes;
    state.painting->ForEachBlock([&](const void* block, size_t n) {
      if (blocks.insert(block).second) bytes += n;
    });
  };
  for (const auto& [frames_read, state] : states_) count(state);
  if (adding) count(*adding);
  return bytes;
}

void RunSnapshots::Add(int frames_read, PaintRunState state) {
  last_offered_bytes_ = state.bytes();
  if (last_offered_bytes_ > budget_bytes_) return;  // one state alone over the budget: none kept
  // Thinned until the new state fits: the spacing doubles, every state off it dropped.
  while (HeldBytes(&state) > budget_bytes_ && states_.size() > 1) DoubleTheSpacing();
  // Room for one state only: the newest replaces the one kept (the first too), the spacing
  // doubling each time (saves stay few); a step back then paints at most the frames since the
  // state kept, not every frame from the first.
  if (HeldBytes(&state) > budget_bytes_) {
    states_.clear();
    every_ *= 2;
  } else if (frames_read % every_ != 0) {
    bytes_ = HeldBytes(nullptr);
    return;
  }
  states_[frames_read] = std::move(state);
  bytes_ = HeldBytes(nullptr);
}

void RunSnapshots::Costs(double save_seconds, double painting_seconds) {
  if (painting_seconds > 0 && save_seconds > kMaxSaveShare * painting_seconds) every_ *= 2;
}

const PaintRunState* RunSnapshots::AtOrBefore(int frames_read, int* its_frames_read) const {
  auto it = states_.upper_bound(frames_read);
  if (it == states_.begin()) return nullptr;
  --it;
  *its_frames_read = it->first;
  return &it->second;
}

}  // namespace fresco
