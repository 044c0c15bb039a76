#include "app/commands.h"

namespace fresco {

int RunVerbSynth(const CommandArgs& args) { return kExitFailure; }

}  // namespace fresco
