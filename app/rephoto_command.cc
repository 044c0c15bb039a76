// `fresco rephoto PROJECT.json --out DIR [--every N] [--set KEY=VALUE ...] [--quiet]`: scores a
// project on its own frames (virtual rephotography, pipeline/rephoto/): each frame with a pose
// (or every N-th) left out in turn, the model painted from the others, rendered at its pose
// and compared with it. Writes DIR/rephoto.json, DIR/rephoto.md (also printed) and
// DIR/views/NAME.png (the render beside the photo).
#include <cctype>
#include <chrono>
#include <cstdio>
#include <iostream>

#include "app/commands.h"
#include "app/interrupt.h"
#include "app/progress.h"
#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_io.h"
#include "pipeline/rephoto/rephoto_report.h"
#include "pipeline/rephoto/rephoto_run.h"

namespace fresco {
namespace {

ArgSpec RephotoSpec() {
  ArgSpec spec;
  spec.usage = "fresco rephoto PROJECT.json --out DIR [--every N] [--set KEY=VALUE ...] [--quiet]";
  spec.help =
      "Scores how the painted model looks from where the photos were taken, with no ground\n"
      "truth (virtual rephotography): each frame with a pose (or every N-th) is left out in\n"
      "turn, the model is painted from the other frames with the project's settings, rendered\n"
      "at the left-out frame's pose and compared with it: PSNR over the pixels where painted\n"
      "surface is seen, 1 - NCC (local 9x9 normalized cross-correlation of the grey values,\n"
      "mask eroded by 9x9: insensitive to exposure, sensitive to blur, seams and\n"
      "misalignment), completeness (surface pixels that are painted) and the painting's wall\n"
      "time. Writes DIR/rephoto.json (per frame, and mean, median and worst), DIR/rephoto.md\n"
      "(the same as a table, also printed) and DIR/views/NAME.png (the render beside the\n"
      "photo). One paint run per left-out frame: --every trades time for coverage on videos.\n\n"
      "  --every N        leave out the first frame with a pose and every N-th after it\n"
      "                   (default 1: every frame)\n"
      "  --set KEY=VALUE  a project setting by JSON path, as for fresco run (repeatable)\n"
      "  --quiet          no progress on stderr\n\n"
      "Ctrl-C (or SIGTERM) stops at the next frame and writes no tables.";
  spec.min_positional = spec.max_positional = 1;
  spec.options = {"--out", "--every"};
  spec.repeatable = {"--set"};
  spec.switches = {"--quiet"};
  spec.required = {"--out"};
  return spec;
}

// A frame name as a file name: path separators and odd characters become '_'.
std::string FileStem(const std::string& name) {
  std::string stem = name.substr(0, name.rfind('.'));
  for (char& c : stem)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_')) c = '_';
  return stem.empty() ? "frame" : stem;
}

}  // namespace

int RunVerbRephoto(const CommandArgs& argv) {
  const ArgSpec spec = RephotoSpec();
  Args args;
  if (int code = ParseVerbArgs("rephoto", argv, spec, &args); code >= 0) return code;
  const std::string out_dir = args.Get("--out");
  RephotoOptions options;
  options.overrides = args.All("--set");
  std::string error;
  if (args.Has("--every") && !ParseInt(args.Get("--every"), "--every", &options.every, &error))
    return UsageError("rephoto", spec, error);
  if (Status s = options.Check(); !s.ok()) return UsageError("rephoto", spec, s.message());
  if (Status s = MakeDirectories(out_dir + "/views"); !s.ok()) return Fail(s);

  const bool quiet = args.Switch("--quiet");
  options.progress = ProgressLines("rephoto", quiet);
  InterruptCatcher interrupt;
  options.stop = [] { return Interrupted(); };
  Status write_error;  // writing a view failed: not bad input
  const RephotoViewSink sink = [&](const RephotoFrame& frame, const cv::Mat& rendered,
                                   const cv::Mat& photo) {
    write_error = WriteImageAtomic(out_dir + "/views/" + FileStem(frame.name) + ".png",
                                   SideBySide(frame, rendered, photo));
    return write_error;
  };
  RephotoResult result;
  const Status status = RunRephoto(args.positional[0], options, sink, &result);
  if (Interrupted()) {
    std::fprintf(stderr, "fresco rephoto: interrupted by %s; no tables written to %s\n",
                 InterruptSignalName().c_str(), out_dir.c_str());
    return InterruptExitCode();
  }
  if (!write_error.ok()) {
    return Fail(write_error);
  }
  if (!status.ok()) return Fail(status);
  const RephotoSummary summary = SummarizeRephoto(result);
  const std::string text = RephotoToMarkdown(result, summary);
  for (const auto& [path, contents] :
       {std::pair{out_dir + "/rephoto.json",
                  RephotoToJson(result, options.overrides, options.every, summary)},
        std::pair{out_dir + "/rephoto.md", text}}) {
    if (Status s = WriteFileAtomic(path, contents); !s.ok()) {
      return Fail(s);
    }
  }
  std::cout << text;
  if (!quiet)
    std::fprintf(stderr,
                 "fresco rephoto: %zu frames -> %s/rephoto.json, %s/rephoto.md, %s/views/\n",
                 result.frames.size(), out_dir.c_str(), out_dir.c_str(), out_dir.c_str());
  return kExitOk;
}

}  // namespace fresco
