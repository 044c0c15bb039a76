// Progress on stderr for long work: a bar redrawn in place when stderr is a terminal, plain
// lines at every 10 % otherwise (logs stay readable), nothing when quiet.
#pragma once

#include <chrono>
#include <functional>
#include <string>

namespace fresco {

// Progress as plain lines on stderr for a library's callback (done, total, line): "LABEL:
// DONE/TOTAL (SECONDS s) LINE", seconds since this call; nothing when quiet.
std::function<void(int done, int total, const std::string& line)> ProgressLines(
    const std::string& label, bool quiet);

class Progress {
 public:
  // `total` < 0: unknown (a live stream), shown as "?".
  Progress(std::string label, int total, bool quiet = false);
  void Update(int done, const std::string& detail = "");
  // The total once it is known better than at the start (e.g. steps added on the way).
  void SetTotal(int total) { total_ = total; }
  void Finish(const std::string& detail = "");
  // Erases the bar (terminal only) so that a message can take its line.
  void Clear();

 private:
  std::string TotalText() const { return total_ < 0 ? std::string("?") : std::to_string(total_); }
  std::string label_;
  int total_;
  bool quiet_;
  bool tty_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace fresco
