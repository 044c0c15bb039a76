// How far a running COLMAP step has got, read from the progress lines it writes to its log
// (logs/NN_STEP.log, colmap_runner.h): feature_extractor's "Processed file [i/N]",
// sequential_matcher's "Matching image [i/N]", exhaustive_matcher's "Matching block [i/N,
// j/N]" (or "[i/N]"), and the mapper's and image_registrator's "Registering image #ID (K)",
// K images registered so far of the `images` it was given. The last such line counts.
#pragma once

#include <string>

namespace fresco {

struct ColmapStepProgress {
  bool known = false;  // a progress line was found
  int done = 0, total = 0;
  double Fraction() const { return known && total > 0 ? static_cast<double>(done) / total : 0.0; }
};

// `log_text`: the step's log so far (or its tail); `images`: the images the step works on
// (the total of the mapper's count; the other steps say theirs).
ColmapStepProgress ReadColmapStepProgress(const std::string& log_text, int images);

// The tail of at most `max_bytes` of the file at `path` ("" when it cannot be read).
std::string ReadFileTail(const std::string& path, size_t max_bytes);

}  // namespace fresco
