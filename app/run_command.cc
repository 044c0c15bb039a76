#include "app/commands.h"

namespace fresco {

int RunVerbRun(const CommandArgs& args) { return kExitFailure; }

}  // namespace fresco
