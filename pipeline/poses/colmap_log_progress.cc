#include "pipeline/poses/colmap_log_progress.h"

#include <algorithm>
#include <cstdio>
#include <fstream>

namespace fresco {
namespace {

// The position of the last `marker` in `text` and the progress it reads there.
struct Found {
  size_t at = std::string::npos;
  int done = 0, total = 0;
};

Found Last(const std::string& text, const std::string& marker, int images) {
  Found found;
  for (size_t at = text.rfind(marker); at != std::string::npos;
       at = at == 0 ? std::string::npos : text.rfind(marker, at - 1)) {
    const std::string rest = text.substr(at + marker.size(), 48);
    int a = 0, b = 0, c = 0, d = 0;
    if (marker == "Registering image #") {
      if (std::sscanf(rest.c_str(), "%d (%d)", &a, &b) != 2) continue;
      found = {at, b, std::max(images, b)};
    } else if (std::sscanf(rest.c_str(), "%d/%d, %d/%d]", &a, &b, &c, &d) == 4 && b > 0 && d > 0) {
      found = {at, (a - 1) * d + c, b * d};  // block (a, c) of b x d blocks
    } else if (std::sscanf(rest.c_str(), "%d/%d]", &a, &b) == 2 && b > 0) {
      found = {at, a, b};
    } else {
      continue;
    }
    return found;
  }
  return found;
}

}  // namespace

ColmapStepProgress ReadColmapStepProgress(const std::string& log_text, int images) {
  Found best;
  for (const char* marker :
       {"Processed file [", "Matching image [", "Matching block [", "Registering image #"}) {
    const Found found = Last(log_text, marker, images);
    if (found.at != std::string::npos && (best.at == std::string::npos || found.at > best.at))
      best = found;
  }
  ColmapStepProgress progress;
  if (best.at == std::string::npos || best.total <= 0) return progress;
  progress.known = true;
  progress.total = best.total;
  progress.done = std::clamp(best.done, 0, best.total);
  return progress;
}

std::string ReadFileTail(const std::string& path, size_t max_bytes) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return "";
  const std::streamoff size = in.tellg();
  const std::streamoff start = size > static_cast<std::streamoff>(max_bytes)
                                   ? size - static_cast<std::streamoff>(max_bytes)
                                   : 0;
  in.seekg(start);
  std::string text(static_cast<size_t>(size - start), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<size_t>(in.gcount()));
  return text;
}

}  // namespace fresco
