#include "app/progress.h"

#include <unistd.h>

#include <cstdio>

namespace fresco {

Progress::Progress(std::string label, int total, bool quiet)
    : label_(std::move(label)), total_(total), quiet_(quiet), tty_(isatty(STDERR_FILENO) != 0) {
  start_ = last_draw_ = std::chrono::steady_clock::now();
}

void Progress::Update(int done, const std::string& detail) {
  if (quiet_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  const double fraction = total_ > 0 ? static_cast<double>(done) / total_ : 0.0;
  if (tty_) {
    const bool last = total_ > 0 && done >= total_;  // unknown totals (live): rate-limited too
    if (!last && now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    const int width = 30;
    const int filled = static_cast<int>(fraction * width);
    std::fprintf(stderr, "\r%s [%s%s] %d/%s %.1fs %s\033[K", label_.c_str(),
                 std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), done,
                 TotalText().c_str(), elapsed_s, detail.c_str());
    std::fflush(stderr);
    return;
  }
  const int decile = total_ > 0 ? static_cast<int>(fraction * 10) : done / 100;
  if (decile == last_decile_) return;
  last_decile_ = decile;
  std::fprintf(stderr, "%s: %d/%s (%.1fs) %s\n", label_.c_str(), done, TotalText().c_str(),
               elapsed_s, detail.c_str());
}

void Progress::Finish(const std::string& detail) {
  if (quiet_) return;
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::fprintf(stderr, "%s%s: done in %.1fs %s\n", tty_ ? "\r\033[K" : "", label_.c_str(),
               elapsed_s, detail.c_str());
}

void Progress::Clear() {
  if (quiet_ || !tty_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
}

std::function<void(int done, int total, const std::string& line)> ProgressLines(
    const std::string& label, bool quiet) {
  const auto start = std::chrono::steady_clock::now();
  return [label, quiet, start](int done, int total, const std::string& line) {
    if (quiet) return;
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "%s: %d/%d (%.0f s) %s\n", label.c_str(), done, total, s, line.c_str());
  };
}

}  // namespace fresco
