// Verbs whose issues have not landed yet. Each says so plainly and exits 1; each file that
// implements one of them removes it from here.
#include <iostream>

#include "app/commands.h"

namespace fresco {

static int NotYet(const std::string& verb, const std::string& issue, const CommandArgs& argv) {
  ArgSpec spec;
  spec.usage = "fresco " + verb + " ...";
  spec.max_positional = 1000;
  Args args;
  for (const std::string& a : argv) {
    if (a == "--help" || a == "-h") {
      std::cout << "usage: " << spec.usage << "\n\nnot implemented yet (" << issue << ")\n";
      return kExitOk;
    }
  }
  std::cerr << "fresco " << verb << ": not implemented yet (" << issue << ")\n";
  return kExitFailure;
}

int RunVerbBench(const CommandArgs& a) { return NotYet("bench", "issue 10", a); }

}  // namespace fresco
