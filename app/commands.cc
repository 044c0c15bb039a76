#include "app/commands.h"

#include <algorithm>
#include <exception>
#include <iostream>
#include <string>

#include "pipeline/run/frame_policy.h"

namespace fresco {

const std::vector<Command>& AllCommands() {
  static const std::vector<Command> kCommands = {
      {"run", "paint a project's video onto its model (headless)", RunVerbRun},
      {"merge", "join the parts `run --shard I/N` painted into one run's outputs", RunVerbMerge},
      {"slurm", "write (and submit) Slurm jobs painting a project in shards, then merging", RunVerbSlurm},
      {"render", "render a (painted or original) glTF, PLY or OBJ model through a camera", RunVerbRender},
      {"synth", "make a synthetic capture from a glTF scene", RunVerbSynth},
      {"group", "show, or store in the project, the base-buffer grouping", RunVerbGroup},
      {"calib", "calibrate camera intrinsics from board images (mrcal)", RunVerbCalib},
      {"poses", "bootstrap or verify poses with COLMAP", RunVerbPoses},
      {"bench", "measure the speed/accuracy trade of pipeline settings", RunVerbBench},
      {"eval", "score a setting over a suite of synthetic captures", RunVerbEval},
      {"rephoto", "score a project on its own photos: each left out, painted from the others", RunVerbRephoto},
      {"settings", "list the project file's settings: default, range, what each does", RunVerbSettings},
      {"gui", "the authoring app", RunVerbGui},
  };
  return kCommands;
}

static void PrintMainUsage(std::ostream& out) {
  out << "usage: fresco VERB [ARGS...]   (fresco VERB --help for a verb's options;\n"
         "       fresco --version prints the version)\n\nverbs:\n";
  size_t width = 0;  // the summaries line up one space after the longest verb
  for (const Command& c : AllCommands()) width = std::max(width, std::string(c.verb).size());
  for (const Command& c : AllCommands()) {
    out << "  " << c.verb << std::string(width + 1 - std::string(c.verb).size(), ' ')
        << c.summary << "\n";
  }
}


int Dispatch(const std::vector<std::string>& argv) {
  if (argv.empty()) {
    PrintMainUsage(std::cerr);
    return kExitBadInput;
  }
  const std::string& verb = argv[0];
  if (verb == "--help" || verb == "-h" || verb == "help") {
    PrintMainUsage(std::cout);
    return kExitOk;
  }
  if (verb == "--version" || verb == "version") {
    std::cout << "fresco " << FRESCO_VERSION << "\n";
    return kExitOk;
  }
  for (const Command& c : AllCommands()) {
    if (verb != c.verb) continue;
    try {
      return c.run(CommandArgs(argv.begin() + 1, argv.end()));
    } catch (...) {
      std::cerr << "fresco " << verb << ": " << FailureMessage(std::current_exception()) << "\n";
      return kExitFailure;
    }
  }
  std::cerr << "fresco: unknown verb '" << verb << "'\n";
  PrintMainUsage(std::cerr);
  return kExitBadInput;
}

int ParseVerbArgs(const std::string& verb, const CommandArgs& argv, const ArgSpec& spec,
                  Args* args) {
  std::string error;
  if (!ParseArgs(argv, spec, args, &error)) return UsageError(verb, spec, error);
  if (args->help) {
    std::cout << "usage: " << spec.usage << "\n";
    if (!spec.help.empty()) std::cout << "\n" << spec.help << "\n";
    return kExitOk;
  }
  return -1;
}

int UsageError(const std::string& verb, const ArgSpec& spec, const std::string& message) {
  std::cerr << "fresco " << verb << ": " << message << "\nusage: " << spec.usage << "\n";
  return kExitBadInput;
}

int ExitCodeFor(const Status& status) {
  switch (status.kind()) {
    case StatusKind::kOk:
      return kExitOk;
    case StatusKind::kBadInput:
      return kExitBadInput;
    case StatusKind::kOutput:
    case StatusKind::kFailed:
    case StatusKind::kInternal:
      return kExitFailure;
  }
  return kExitFailure;
}

int Fail(const Status& status) {
  std::cerr << "error: " << status.message() << "\n";
  return ExitCodeFor(status);
}

}  // namespace fresco
