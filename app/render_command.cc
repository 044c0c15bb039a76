#include "app/commands.h"

namespace fresco {

int RunVerbRender(const CommandArgs& args) { return kExitFailure; }

}  // namespace fresco
