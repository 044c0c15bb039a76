// fresco slurm PROJECT.json --out DIR --shards N [--submit] [--sbatch "OPTIONS"]: writes a
// Slurm array job painting the project in N shards (`fresco run --shard I/N` into
// DIR/parts/I) and a job merging them into DIR after the array succeeds; --submit submits
// both with the `sbatch` on PATH (the cluster SLURM_CONF names); a project that needs the
// whole-capture pre-pass gets a job running it once first, which the array waits for.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "app/commands.h"
#include "pipeline/core/atomic_file.h"
#include "pipeline/core/project.h"
#include "pipeline/core/run_process.h"
#include "pipeline/run/prepass_file.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

ArgSpec SlurmSpec() {
  ArgSpec spec;
  spec.usage =
      "fresco slurm PROJECT.json --out DIR --shards N [--submit] [--sbatch \"OPTIONS\"]\n"
      "       [--set KEY=VALUE ...]";
  spec.help =
      "Paints a project on a Slurm cluster in N shards: writes DIR/paint.sbatch (an array job,\n"
      "task I running `fresco run PROJECT --out DIR/parts/I --shard I/N`) and\n"
      "DIR/merge.sbatch (`fresco merge DIR/parts/0 ... --out DIR`, to run after every task\n"
      "succeeded: --dependency=afterok). With more than one shard, or when the project's\n"
      "settings need the whole-capture pre-pass (the joint pose check, movers found across\n"
      "views), DIR/prepass.sbatch runs it once first (`fresco run --prepass DIR/prepass.json\n"
      "--prepass-only`: the pre-pass and the charts' layout) and every task reads its outcome\n"
      "(--prepass). DIR/painted.gltf and DIR/metrics.json appear when the\n"
      "merge job ends. DIR must be on a file system every node sees; the jobs run this\n"
      "fresco executable by its absolute path. Logs: DIR/logs/. A failed task: resubmit\n"
      "that index (sbatch --array=I DIR/paint.sbatch), then DIR/merge.sbatch.\n\n"
      "  --shards N        shards (array tasks), N >= 1\n"
      "  --submit          submit the jobs with `sbatch` on PATH (each after the one before\n"
      "                    succeeded) and print their ids\n"
      "  --sbatch OPTIONS  extra sbatch options for every job, e.g. \"--partition=big --mem=8G\"\n"
      "                    (written as #SBATCH lines)\n"
      "  --set KEY=VALUE   project settings passed to every shard (as `fresco run`'s)";
  spec.min_positional = spec.max_positional = 1;
  spec.options = {"--out", "--shards", "--sbatch"};
  spec.repeatable = {"--set"};
  spec.switches = {"--submit"};
  spec.required = {"--out", "--shards"};
  return spec;
}

std::string ThisExecutable() {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  return error ? std::string("fresco") : self.string();
}

// A job script's head: its #SBATCH lines (`own` then the user's `extra`), before any command.
std::string Header(const std::string& name, const std::string& log,
                   const std::vector<std::string>& own, const std::vector<std::string>& extra) {
  std::string s = "#!/bin/bash\n# Written by `fresco slurm` (docs/guide/slurm.md).\n";
  s += "#SBATCH --job-name=" + name + "\n#SBATCH --output=" + log + "\n";
  for (const std::string& option : own) s += "#SBATCH " + option + "\n";
  for (const std::string& option : extra) s += "#SBATCH " + option + "\n";
  return s + "set -euo pipefail\n";
}

// The job id `sbatch --parsable` printed last in `log` ("ID" or "ID;CLUSTER").
std::string LastJobId(const std::string& log) {
  std::string text, line, last;
  if (!ReadFileToString(log, &text).ok()) return "";
  std::istringstream lines(text);
  while (std::getline(lines, line))
    if (!line.empty()) last = line;
  last = last.substr(0, last.find(';'));
  for (char c : last)
    if (c < '0' || c > '9') return "";
  return last;
}

Status Submit(const std::vector<std::string>& argv, const std::string& log, std::string* id) {
  int code = 0;
  FRESCO_RETURN_IF_ERROR(RunProcess(argv, log, &code));
  *id = LastJobId(log);
  if (code != 0 || id->empty())
    return Status::Failed(argv[0] + " " + argv.back() + ": failed (exit " + std::to_string(code) +
                          "; see " + log + ")");
  return Status::Ok();
}

}  // namespace

int RunVerbSlurm(const CommandArgs& argv) {
  const ArgSpec spec = SlurmSpec();
  Args args;
  if (int code = ParseVerbArgs("slurm", argv, spec, &args); code >= 0) return code;
  const std::string shards_text = args.Get("--shards");
  int shards = 0;
  if (shards_text.empty() || shards_text.size() > 6 ||
      shards_text.find_first_not_of("0123456789") != std::string::npos ||
      (shards = std::stoi(shards_text)) < 1)
    return Fail(Status::Error("--shards: '" + shards_text + "' is not a whole number >= 1"));
  // The project must load (with its --set) before jobs that would fail on it are queued.
  Project project;
  if (Status s = LoadProject(args.positional[0], args.All("--set"), &project); !s.ok())
    return Fail(s);
  const std::string dir = fs::absolute(args.Get("--out")).lexically_normal().string();
  const std::string project_path = fs::absolute(args.positional[0]).lexically_normal().string();
  std::vector<std::string> extra;
  {
    std::istringstream words(args.Get("--sbatch"));
    for (std::string w; words >> w;) extra.push_back(w);
  }
  const std::string fresco = ThisExecutable();
  std::string sets;
  for (const std::string& set : args.All("--set")) sets += " --set " + ShellQuote(set);
  const std::string n = std::to_string(shards);
  // The whole-capture pre-pass and the charts' layout, found once before the array (which
  // reads them): when the settings need the pre-pass, or there is more than one shard (each
  // then builds only its own charts, where no chart is coupled).
  const bool prepass = NeedsWholeCapturePrepass(project) || shards > 1;
  const std::string prepass_file = dir + "/prepass.json";
  std::string prepass_job = Header("fresco-prepass", dir + "/logs/prepass.out", {}, extra);
  prepass_job += "exec " + ShellQuote(fresco) + " run " + ShellQuote(project_path) + " --prepass " +
                 ShellQuote(prepass_file) + " --prepass-only --quiet" + sets + "\n";
  std::string paint = Header("fresco-paint", dir + "/logs/paint-%a.out",
                             {"--array=0-" + std::to_string(shards - 1)}, extra);
  paint += "I=${SLURM_ARRAY_TASK_ID:?run as a Slurm array task}\n";
  paint += "exec " + ShellQuote(fresco) + " run " + ShellQuote(project_path) + " --out " +
           ShellQuote(dir + "/parts/") + "\"$I\" --shard \"$I/" + n + "\" --quiet" + sets +
           (prepass ? " --prepass " + ShellQuote(prepass_file) : std::string()) + "\n";
  // A failed shard cancels the merge (else it would wait forever, DependencyNeverSatisfied).
  std::string merge =
      Header("fresco-merge", dir + "/logs/merge.out", {"--kill-on-invalid-dep=yes"}, extra);
  merge += "exec " + ShellQuote(fresco) + " merge";
  for (int i = 0; i < shards; ++i) merge += " " + ShellQuote(dir + "/parts/" + std::to_string(i));
  merge += " --out " + ShellQuote(dir) + " --quiet\n";
  if (Status s = MakeDirectories(dir + "/logs"); !s.ok()) return Fail(s);
  if (prepass)
    if (Status s = WriteFileAtomic(dir + "/prepass.sbatch", prepass_job); !s.ok()) return Fail(s);
  if (Status s = WriteFileAtomic(dir + "/paint.sbatch", paint); !s.ok()) return Fail(s);
  if (Status s = WriteFileAtomic(dir + "/merge.sbatch", merge); !s.ok()) return Fail(s);
  if (!args.Switch("--submit")) {
    if (prepass) std::printf("%s/prepass.sbatch\n", dir.c_str());
    std::printf("%s/paint.sbatch\n%s/merge.sbatch\n", dir.c_str(), dir.c_str());
    return kExitOk;
  }
  const std::string sbatch = FindProgram("sbatch");
  if (sbatch.empty())
    return Fail(
        Status::Error("--submit: sbatch not found on PATH (install Slurm's client, or "
                      "submit DIR/paint.sbatch and DIR/merge.sbatch by hand)"));
  const std::string log = dir + "/logs/sbatch.log";
  std::string prepass_id, paint_id, merge_id;
  std::vector<std::string> paint_argv = {sbatch, "--parsable"};
  if (prepass) {
    if (Status s = Submit({sbatch, "--parsable", dir + "/prepass.sbatch"}, log, &prepass_id);
        !s.ok())
      return Fail(s);
    std::printf("prepass %s\n", prepass_id.c_str());
    // A failed pre-pass cancels the array (and so the merge) instead of leaving it waiting.
    paint_argv.insert(paint_argv.end(),
                      {"--dependency=afterok:" + prepass_id, "--kill-on-invalid-dep=yes"});
  }
  paint_argv.push_back(dir + "/paint.sbatch");
  if (Status s = Submit(paint_argv, log, &paint_id); !s.ok()) return Fail(s);
  if (Status s =
          Submit({sbatch, "--parsable", "--dependency=afterok:" + paint_id, dir + "/merge.sbatch"},
                 log, &merge_id);
      !s.ok())
    return Fail(s);
  std::printf("paint %s\nmerge %s\n", paint_id.c_str(), merge_id.c_str());
  return kExitOk;
}

}  // namespace fresco
