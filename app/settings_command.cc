// `fresco settings [PREFIX] [--markdown]`: every project-file setting (or those whose key
// starts with PREFIX) with its default, range and what it does, from the same declarations
// the project-file reader checks (pipeline/core/settings.h).
#include <iostream>
#include <string>

#include "app/commands.h"
#include "pipeline/core/settings.h"

namespace fresco {
namespace {

ArgSpec SettingsSpec() {
  ArgSpec spec;
  spec.usage = "fresco settings [PREFIX] [--markdown]";
  spec.help =
      "Lists the project file's settings: key (as for --set), default, range and what it\n"
      "does; only the keys that start with PREFIX when given (e.g. pipeline.background).\n\n"
      "  --markdown  one table row per setting, as in docs/reference/project-file.md";
  spec.min_positional = 0;
  spec.max_positional = 1;
  spec.switches = {"--markdown"};
  return spec;
}

}  // namespace

int RunVerbSettings(const CommandArgs& argv) {
  const ArgSpec spec = SettingsSpec();
  Args args;
  if (int code = ParseVerbArgs("settings", argv, spec, &args); code >= 0) return code;
  const std::string prefix = args.positional.empty() ? "" : args.positional[0];
  if (args.Switch("--markdown")) {
    const std::vector<std::string> rows = SettingsTableRows(prefix);
    if (rows.empty())
      return UsageError("settings", spec, "no setting starts with '" + prefix + "'");
    for (const std::string& row : rows) std::cout << row << "\n";
    return kExitOk;
  }
  Project defaults;
  int shown = 0;
  for (const Setting& s : DescribeSettings(&defaults)) {
    if (s.key.compare(0, prefix.size(), prefix) != 0) continue;
    std::cout << s.key << " = " << s.ValueText() << "  (" << s.RangeText() << ")\n    " << s.help
              << "\n";
    ++shown;
  }
  if (shown == 0) return UsageError("settings", spec, "no setting starts with '" + prefix + "'");
  return kExitOk;
}

}  // namespace fresco
