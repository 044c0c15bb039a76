// The `fresco` verbs. Each verb is a function in its own file taking the arguments after the
// verb; the dispatcher maps verb -> function. Exit codes (docs/contract.md): 0 success, 2 bad
// usage or bad input (one line on stderr naming file and field), 1 anything else. A verb
// never picks 1 or 2 by hand after a Status: it returns Fail(status), whose kind decides.
#pragma once

#include <string>
#include <vector>

#include "app/args.h"
#include "pipeline/core/status.h"

namespace fresco {

constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;

using CommandArgs = std::vector<std::string>;

struct Command {
  const char* verb;
  const char* summary;
  int (*run)(const CommandArgs& args);
};

// Every verb, in the order `fresco --help` lists them.
const std::vector<Command>& AllCommands();
// Runs `fresco ARGS...` (argv[0] excluded); never throws.
int Dispatch(const std::vector<std::string>& argv);

// Parses a verb's arguments. Returns -1 when the verb should go on; otherwise the exit code
// (0 after printing --help, 2 after printing a usage error).
int ParseVerbArgs(const std::string& verb, const CommandArgs& argv, const ArgSpec& spec,
                  Args* args);
// Prints "fresco VERB: message" and the usage line; returns 2.
int UsageError(const std::string& verb, const ArgSpec& spec, const std::string& message);
// The exit code for a Status, by its kind: 0 ok, 2 bad input, 1 anything else (output,
// failed, internal). Every verb's exit code after a Status comes from here.
int ExitCodeFor(const Status& status);
// Prints a failed Status as one line "error: MESSAGE" on stderr; returns ExitCodeFor(status).
int Fail(const Status& status);

int RunVerbRun(const CommandArgs& args);
int RunVerbRender(const CommandArgs& args);
int RunVerbMerge(const CommandArgs& args);
int RunVerbSlurm(const CommandArgs& args);
int RunVerbGroup(const CommandArgs& args);
int RunVerbSynth(const CommandArgs& args);
int RunVerbCalib(const CommandArgs& args);
int RunVerbPoses(const CommandArgs& args);
int RunVerbBench(const CommandArgs& args);
int RunVerbEval(const CommandArgs& args);
int RunVerbRephoto(const CommandArgs& args);
int RunVerbSettings(const CommandArgs& args);
int RunVerbGui(const CommandArgs& args);

}  // namespace fresco
