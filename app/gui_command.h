// `fresco gui ...` as the `fresco-gui` executable runs it (gui_command.cc): parses the
// verb's arguments (bad input is exit 2 before any window opens) and runs the app.
#pragma once

#include "app/commands.h"

namespace fresco {

int RunGuiCommand(const CommandArgs& args);

}  // namespace fresco
