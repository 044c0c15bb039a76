// `fresco eval SUITE.json --out DIR [--set KEY=VALUE ...]`: runs one setting over an
// evaluation suite of synthetic captures (pipeline/eval/) and reports the distribution per
// capture and per family: DIR/eval.json and DIR/eval.md (also printed).
#include <chrono>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "app/commands.h"
#include "app/interrupt.h"
#include "app/progress.h"
#include "pipeline/core/atomic_file.h"
#include "pipeline/core/project.h"
#include "pipeline/eval/eval_run.h"
#include "pipeline/eval/eval_summary.h"

namespace fresco {
namespace {

ArgSpec EvalSpec() {
  ArgSpec spec;
  spec.usage =
      "fresco eval SUITE.json --out DIR [--set KEY=VALUE ...] [--cache DIR] [--only NAMES]\n"
      "       [--holdout N] [--recovery] [--quiet]";
  spec.help =
      "Generates the suite's synthetic captures (cached: a capture is written again only when\n"
      "its spec or the generator changed), paints each with the project settings plus the\n"
      "--set overrides while every N-th frame is held out, and scores the held-out frames:\n"
      "rephotography at the given poses (PSNR, 1-NCC), truth at the true poses (the painted\n"
      "model against the static scene rendered with the frame's exposure), the mover leak\n"
      "(painted pixels there that show a moving object) and the painting speed. Writes\n"
      "DIR/eval.json (per capture, per family median and worst) and DIR/eval.md (tables,\n"
      "also printed).\n\n"
      "  --set KEY=VALUE  a project setting by JSON path, as for fresco run (repeatable)\n"
      "  --cache DIR      where the captures are generated (default DIR/captures); share\n"
      "                   it between runs of different settings\n"
      "  --only NAMES     comma-separated capture or family names to run (default: all)\n"
      "  --holdout N      every N-th frame is held out of painting and scored (default 10)\n"
      "  --recovery       also paint each capture without any pose correction (refinement\n"
      "                   off, no joint adjustment), and those with noisy poses at their\n"
      "                   true poses: reports the share of the PSNR lost to\n"
      "                   pose noise that the setting recovers, and what it costs on exact\n"
      "                   poses (about 2.5 times as long)\n"
      "  --quiet          no progress on stderr\n\n"
      "Ctrl-C (or SIGTERM) stops at the next frame and writes nothing.";
  spec.min_positional = spec.max_positional = 1;
  spec.options = {"--out", "--cache", "--only", "--holdout"};
  spec.repeatable = {"--set"};
  spec.switches = {"--quiet", "--recovery"};
  spec.required = {"--out"};
  return spec;
}

std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, ',');)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

}  // namespace

int RunVerbEval(const CommandArgs& argv) {
  const ArgSpec spec = EvalSpec();
  Args args;
  if (int code = ParseVerbArgs("eval", argv, spec, &args); code >= 0) return code;
  const std::string out_dir = args.Get("--out");
  EvalOptions options;
  options.overrides = args.All("--set");
  options.cache_dir = args.Has("--cache") ? args.Get("--cache") : out_dir + "/captures";
  options.recovery = args.Switch("--recovery");
  std::string error;
  if (args.Has("--holdout") &&
      !ParseInt(args.Get("--holdout"), "--holdout", &options.holdout, &error))
    return UsageError("eval", spec, error);
  if (options.holdout < 2) return UsageError("eval", spec, "--holdout: must be >= 2");

  EvalSuite suite;
  if (Status s = LoadEvalSuite(args.positional[0], &suite); !s.ok()) return Fail(s);
  if (Status s = SelectSuiteCaptures(SplitCommas(args.Get("--only")), &suite); !s.ok())
    return Fail(s);
  if (Status s = MakeDirectories(out_dir); !s.ok()) return Fail(s);
  if (Status s = MakeDirectories(options.cache_dir); !s.ok()) return Fail(s);

  const bool quiet = args.Switch("--quiet");
  options.progress = ProgressLines("eval", quiet);
  InterruptCatcher interrupt;
  options.stop = [] { return Interrupted(); };
  std::vector<CaptureEval> results;
  const Status status = EvaluateSuite(suite, options, &results);
  if (Interrupted()) {
    std::fprintf(stderr, "fresco eval: interrupted by %s; nothing written to %s\n",
                 InterruptSignalName().c_str(), out_dir.c_str());
    return InterruptExitCode();
  }
  if (!status.ok()) return Fail(status);
  const std::vector<FamilySummary> families = SummarizeByFamily(results);
  const std::string text = EvalToText(results, families);
  for (const auto& [path, contents] :
       {std::pair{out_dir + "/eval.json", EvalToJson(options.overrides, results, families)},
        std::pair{out_dir + "/eval.md", text}}) {
    if (Status s = WriteFileAtomic(path, contents); !s.ok()) {
      return Fail(s);
    }
  }
  std::cout << text;
  if (!quiet)
    std::fprintf(stderr, "fresco eval: %zu captures -> %s/eval.json, %s/eval.md\n", results.size(),
                 out_dir.c_str(), out_dir.c_str());
  return kExitOk;
}

}  // namespace fresco
