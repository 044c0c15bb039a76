// One widget per project-file setting, made from its declaration (pipeline/core/settings.h):
// a checkbox, a list of names, or a number dragged within the range the project file
// accepts; the tooltip says what it does, its range and its key.
#pragma once

#include "pipeline/core/settings.h"

namespace fresco {

// Draws the widget; true when an edit is complete (a toggle, a choice, a drag released or
// a typed value entered): the caller records it (undo) then.
bool DrawSettingWidget(const Setting& setting);

// The widget's label: the key's last part, words apart ("window_frames" -> "window frames").
std::string SettingLabel(const Setting& setting);

}  // namespace fresco
