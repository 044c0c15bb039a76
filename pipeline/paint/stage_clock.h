// Small helpers the paint stages share (paint_stages.h): wall time of a stage, and the
// buffers a per-buffer flag marks.
#pragma once

#include <chrono>
#include <cstddef>
#include <vector>

namespace fresco {

// Milliseconds since `start`.
inline double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// The indices where `flags` is true.
inline std::vector<size_t> Indices(const std::vector<bool>& flags) {
  std::vector<size_t> out;
  for (size_t i = 0; i < flags.size(); ++i)
    if (flags[i]) out.push_back(i);
  return out;
}

}  // namespace fresco
