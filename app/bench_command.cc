// `fresco bench PROJECT.json --out DIR [--sweep KEY=V1,V2,... ...]` (docs/contract.md): runs the
// project once per combination of the swept settings and measures speed (fps, per-stage
// ms) against accuracy. Accuracy needs no ground truth: every `--holdout`-th frame is left
// out of painting and the painted model, rendered at its pose, is compared with it (virtual
// rephotography); a synthetic project's true poses add the same comparison at the truth.
// Writes DIR/bench.json and DIR/pareto.png.
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>

#include "app/commands.h"
#include "app/interrupt.h"
#include "app/pareto_plot.h"
#include "app/progress.h"
#include "pipeline/core/atomic_file.h"
#include "pipeline/core/capture.h"
#include "pipeline/core/image_io.h"
#include "pipeline/paint/auto_modes.h"
#include "pipeline/rephoto/holdout_scorer.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/run/paint_run.h"

namespace fresco {
namespace {

ArgSpec BenchSpec() {
  ArgSpec spec;
  spec.usage =
      "fresco bench PROJECT.json --out DIR [--sweep KEY=V1,V2,... ...] [--holdout N]\n"
      "       [--no-baseline] [--quiet]";
  spec.help =
      "Runs the project once per combination of the swept settings (cartesian product of the\n"
      "--sweep options; without any, a default sweep that varies one setting at a time from\n"
      "the project's own: sampling, texel size, occlusion, background model, refinement,\n"
      "threads) and writes DIR/bench.json (one row per run: settings, fps, stage_ms, accuracy)\n"
      "and DIR/pareto.png (fps against PSNR, the Pareto front in red).\n\n"
      "  --sweep KEY=V1,V2  a project setting by JSON path and its values (repeatable)\n"
      "  --holdout N        every N-th frame is held out of painting and scored (default 10)\n"
      "  --no-baseline      skip the last run, the naive baseline (per frame a full depth\n"
      "                     render, every texel projected one at a time, cv::remap)\n"
      "  --quiet            no progress on stderr\n\n"
      "Ctrl-C (or SIGTERM) stops at the next frame, writes nothing, keeps the outputs of\n"
      "earlier benches and exits 130 (143).";
  spec.min_positional = spec.max_positional = 1;
  spec.options = {"--out", "--holdout"};
  spec.repeatable = {"--sweep"};
  spec.switches = {"--quiet", "--no-baseline"};
  spec.required = {"--out"};
  return spec;
}

// One run's settings: KEY=VALUE overrides, in order.
using Settings = std::vector<std::pair<std::string, std::string>>;

const std::vector<std::pair<std::string, std::vector<std::string>>>& DefaultSweep() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> sweep = {
      {"pipeline.sampling", {"nearest", "area"}},
      {"pipeline.max_buffer_texels", {"262144"}},
      {"pipeline.occlusion.tolerance_rel", {"0.005", "0.05"}},
      {"pipeline.background.mode", {"off", "average"}},
      {"pipeline.refine.mode", {"robust"}},
      {"pipeline.threads", {"1"}},
  };
  return sweep;
}

Status ParseSweeps(const std::vector<std::string>& sweeps, std::vector<Settings>* runs) {
  runs->assign(1, Settings());
  if (sweeps.empty()) {  // one at a time, from the project's own settings (the first run)
    for (const auto& [key, values] : DefaultSweep())
      for (const std::string& v : values) runs->push_back({{key, v}});
    return Status::Ok();
  }
  for (const std::string& sweep : sweeps) {
    const size_t eq = sweep.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == sweep.size())
      return Status::Error("--sweep '" + sweep + "': expected KEY=V1,V2,...");
    std::vector<std::string> values;
    std::stringstream list(sweep.substr(eq + 1));
    for (std::string v; std::getline(list, v, ',');) {
      if (v.empty()) return Status::Error("--sweep '" + sweep + "': empty value");
      values.push_back(v);
    }
    std::vector<Settings> product;
    for (const Settings& run : *runs)
      for (const std::string& v : values) {
        Settings s = run;
        s.emplace_back(sweep.substr(0, eq), v);
        product.push_back(std::move(s));
      }
    *runs = std::move(product);
  }
  return Status::Ok();
}

struct RunResult {
  nlohmann::json row;
  ParetoPoint point;
};

// Paints the project with `settings` (or, `naive`, with the naive baseline), holding out
// every `holdout`-th frame, and scores.
Status BenchOne(const std::string& project_path, const Settings& settings, int holdout, bool naive,
                RunResult* result) {
  std::vector<std::string> overrides;
  std::string label;
  for (const auto& [key, value] : settings) {
    overrides.push_back(key + "=" + value);
    // The key's last two parts ("refine.mode"): short, and not ambiguous.
    const size_t last = key.rfind('.');
    const size_t before =
        last == std::string::npos || last == 0 ? std::string::npos : key.rfind('.', last - 1);
    label += (label.empty() ? "" : " ") +
             (before == std::string::npos ? key : key.substr(before + 1)) + "=" + value;
  }
  Project project;
  FRESCO_RETURN_IF_ERROR(LoadProject(project_path, overrides, &project));
  const int threads = project.pipeline.threads > 0 ? project.pipeline.threads : -1;
  cv::setNumThreads(threads);
  PaintJobOptions job_options;
  job_options.one_stream_for = "fresco bench";
  job_options.joint_holdout_every = holdout;
  std::unique_ptr<PaintJob> job;
  FRESCO_RETURN_IF_ERROR(OpenPaintJob(project, job_options, &job));
  const Capture& capture = job->captures[0];
  PaintSession* session = job->session.get();

  std::vector<HeldOutFrame> held_out;  // with their true poses where the project has them
  PaintRunOptions run_options;
  run_options.max_frames = project.pipeline.max_frames;
  run_options.holdout_every = holdout;
  run_options.naive = naive;
  PaintRun run(session, job->source.get(), run_options);
  PaintRunHooks hooks;
  hooks.stop = [] { return Interrupted(); };
  hooks.after_frame = [&](const RunFrame& f, const FrameReport*) {
    if (f.fate == FrameFate::kHeldOut) held_out.push_back(HeldOutFrameOf(f, &capture));
    return Status::Ok();
  };
  FRESCO_RETURN_IF_ERROR(RunToEnd(&run, hooks));
  const Status interrupted = Status::Error(project_path + ": interrupted");
  if (Interrupted()) return interrupted;
  const PaintRunStats& stats = run.stats();

  // Accuracy on the held-out frames (at the given poses; at the true poses when known).
  HoldoutScorer scorer(session->PaintedScene(), HoldoutScorerOptions());
  if (!scorer.AddAll(held_out, [] { return Interrupted(); })) return interrupted;
  const HoldoutFigures& figures = scorer.figures();
  nlohmann::json& row = result->row;
  row["settings"] = nlohmann::json::object();
  for (const auto& [key, value] : settings) row["settings"][key] = value;
  if (naive) {
    row["baseline"] = "naive";
    label = "naive baseline";
  }
  row["frames"] = stats.frames;
  row["frames_painted"] = stats.frames_painted;
  row["frames_without_pose"] = stats.frames_without_pose;
  row["seconds"] = stats.seconds;
  row["fps"] = stats.seconds > 0 ? (stats.frames - stats.frames_held_out) / stats.seconds : 0.0;
  row["stage_ms"] = nlohmann::json::object();
  for (const auto& [name, ms] : stats.MeanStageMs()) row["stage_ms"][name] = ms;
  row["holdout_frames"] = stats.frames_held_out;
  // Nothing compared: 0 dB, uncorrelated, nothing complete.
  row["psnr_db"] = figures.scored > 0 ? figures.psnr_db : 0.0;
  row["one_minus_ncc"] = figures.scored > 0 ? figures.one_minus_ncc : 1.0;
  row["completeness"] = figures.frames > 0 ? figures.completeness : 0.0;
  row["coverage"] = session->Coverage();
  // What the `auto` modes decided, with their evidence (null for a mode not auto).
  if (!naive) row["auto"] = nlohmann::json::parse(AutoDecisionsJson(session->auto_decisions()));
  if (figures.truth_scored > 0) {
    row["truth"] = {{"psnr_db", figures.truth_psnr_db},
                    {"one_minus_ncc", figures.truth_one_minus_ncc}};
  }
  result->point = {row["fps"].get<double>(), row["psnr_db"].get<double>(),
                   label.empty() ? "project settings" : label};
  return Status::Ok();
}

}  // namespace

int RunVerbBench(const CommandArgs& argv) {
  const ArgSpec spec = BenchSpec();
  Args args;
  if (int code = ParseVerbArgs("bench", argv, spec, &args); code >= 0) return code;
  const std::string project_path = args.positional[0];
  const std::string out_dir = args.Get("--out");
  int holdout = 10;
  std::string error;
  if (args.Has("--holdout") && !ParseInt(args.Get("--holdout"), "--holdout", &holdout, &error))
    return Fail(Status::Error(error));
  if (holdout < 2) return Fail(Status::Error("--holdout: must be >= 2"));
  std::vector<Settings> runs;
  if (Status s = ParseSweeps(args.All("--sweep"), &runs); !s.ok()) return Fail(s);
  // Every run's settings must load before any runs (a typo fails at once, not after an hour).
  for (const Settings& run : runs) {
    std::vector<std::string> overrides;
    for (const auto& [key, value] : run) overrides.push_back(key + "=" + value);
    Project project;
    if (Status s = LoadProject(project_path, overrides, &project); !s.ok()) return Fail(s);
    if (Status s = CheckOneStream(project, "fresco bench"); !s.ok()) return Fail(s);
  }
  if (Status s = MakeDirectories(out_dir); !s.ok()) return Fail(s);

  InterruptCatcher interrupt;
  Progress progress("bench", static_cast<int>(runs.size()) + !args.Switch("--no-baseline"),
                    args.Switch("--quiet"));
  nlohmann::json rows = nlohmann::json::array();
  std::vector<ParetoPoint> points;
  // The last run: the naive baseline (full depth render + cv::remap per buffer).
  const bool baseline = !args.Switch("--no-baseline");
  const size_t total = runs.size() + (baseline ? 1 : 0);
  for (size_t i = 0; i < total; ++i) {
    RunResult result;
    const bool naive = i == runs.size();
    progress.Update(static_cast<int>(i),
                    "run " + std::to_string(i + 1) + " of " + std::to_string(total) + " started");
    const Status s = BenchOne(project_path, naive ? Settings() : runs[i], holdout, naive, &result);
    if (Interrupted()) {
      progress.Clear();
      std::fprintf(stderr,
                   "fresco bench: interrupted by %s during run %zu of %zu; nothing written to %s "
                   "(outputs of earlier benches there are kept)\n",
                   InterruptSignalName().c_str(), i + 1, total, out_dir.c_str());
      return InterruptExitCode();
    }
    if (!s.ok()) return Fail(s);
    rows.push_back(result.row);
    points.push_back(result.point);
    char detail[160];
    std::snprintf(detail, sizeof detail, "%s: %.1f fps, %.2f dB", result.point.label.c_str(),
                  result.point.fps, result.point.psnr_db);
    progress.Update(static_cast<int>(i + 1), detail);
  }
  progress.Finish();
  for (size_t k : ParetoFront(points)) rows[k]["pareto"] = true;
  if (Status s = WriteFileAtomic(out_dir + "/bench.json", rows.dump(2) + "\n"); !s.ok()) {
    return Fail(s);
  }
  const cv::Mat plot = DrawPareto(points, "fresco bench " + project_path);
  if (Status s = WriteImageAtomic(out_dir + "/pareto.png", plot); !s.ok()) {
    return Fail(s);
  }
  std::fprintf(stderr, "fresco bench: %zu runs -> %s/bench.json, %s/pareto.png\n", total,
               out_dir.c_str(), out_dir.c_str());
  if (Interrupted()) {  // while the outputs were written: they were finished first
    std::fprintf(stderr, "fresco bench: interrupted by %s while writing; finished writing first\n",
                 InterruptSignalName().c_str());
    return InterruptExitCode();
  }
  return kExitOk;
}

}  // namespace fresco
