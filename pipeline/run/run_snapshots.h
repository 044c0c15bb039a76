// Saved states of one painting run (PaintRun::Save), every `every` frames read, to step back
// from: going back to frame M restores the nearest state at or before M and paints on from
// there, instead of painting again from the first frame (the app's step back and seek back).
// The memory they hold is bounded: past the budget the spacing doubles (every other state
// dropped), so the states stay spread over the whole capture; the first (before any frame:
// going back to it spares reopening the project and its whole-capture pre-pass) is kept
// while a later state fits beside it. Where the budget holds one state only (a large model),
// the newest replaces it, the spacing doubling each time. The image blocks two
// states share (painting_state.h) count once.
#pragma once

#include <cstddef>
#include <map>

#include "pipeline/run/paint_run.h"

namespace fresco {

class RunSnapshots {
 public:
  RunSnapshots(int every, size_t budget_bytes);

  // Whether a state is due before reading frame `frames_read` (0-based): none kept there yet,
  // `frames_read` on the spacing, and the last state offered fits the budget (a state is not
  // saved, a costly copy, only to be dropped).
  bool Due(int frames_read) const;
  // Keeps `state` (saved before reading frame `frames_read`), thinning as the budget asks.
  void Add(int frames_read, PaintRunState state);
  // What the state just offered cost to save, against the painting since the state before
  // (seconds, one clock for both): where saving took more than kMaxSaveShare of that, the
  // spacing doubles for the states to come (those kept stay), so that keeping states never
  // costs more than about that share of the painting. A painting whose states grow as it
  // goes (a large model) then saves a few, not one every `every` frames only to drop most.
  static constexpr double kMaxSaveShare = 0.25;
  void Costs(double save_seconds, double painting_seconds);
  // The state with the most frames read at most `frames_read`, or null.
  const PaintRunState* AtOrBefore(int frames_read, int* its_frames_read) const;
  void Clear() { states_.clear(), bytes_ = 0; }

  int every() const { return every_; }
  size_t bytes() const { return bytes_; }  // held, shared blocks once
  size_t count() const { return states_.size(); }

 private:
  int every_;
  size_t budget_bytes_;
  size_t bytes_ = 0;
  size_t last_offered_bytes_ = 0;
  std::map<int, PaintRunState> states_;  // by frames read before it

  void DoubleTheSpacing();  // every state off the new spacing dropped
  // The bytes the states kept hold, with `adding` (null: none) among them.
  size_t HeldBytes(const PaintRunState* adding) const;
};

}  // namespace fresco
