// The project file's settings as data: every scalar setting of `pipeline`, `grouping` and
// `live`, walked from the same field list the reader and writer use (project.cc), with its
// range and what it does. `fresco settings`, the app's settings widgets and the settings
// tables in docs/reference/project-file.md are all made from it, so they cannot drift from
// what the project file accepts.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "pipeline/core/project.h"

namespace fresco {

struct Setting {
  enum class Kind { kBool, kInt, kNumber, kText, kChoice };
  std::string key;  // as in --set: "pipeline.background.window_frames"
  Kind kind = Kind::kNumber;
  double min = -std::numeric_limits<double>::infinity();  // kInt, kNumber: [min, max]
  bool min_exclusive = false;
  double max = std::numeric_limits<double>::infinity();
  std::vector<std::string> choices;  // kChoice (and kText restricted to names)
  std::string help;
  // The field in the project passed to DescribeSettings (one of them, by kind).
  bool* flag = nullptr;
  int* integer = nullptr;
  double* number = nullptr;
  std::string* text = nullptr;
  std::function<int()> get_choice;  // kChoice: index into choices
  std::function<void(int)> set_choice;

  std::string Section() const;    // the key up to its last '.': "pipeline.background"
  std::string Name() const;       // the last part: "window_frames"
  std::string ValueText() const;  // the current value as JSON would write it (names quoted
                                  // with backticks for the docs: `robust`)
  std::string RangeText() const;  // "int 2 to 65535", "> 0 to 90", "bool", "`off`, `robust`"
};

// The settings of `project`, bound to its fields (keep the project alive while using them).
std::vector<Setting> DescribeSettings(Project* project);

// The docs' table rows, "| `key` | default | range | meaning |", for every setting whose key
// starts with `prefix` ("" for all), with the defaults of a new project.
std::vector<std::string> SettingsTableRows(const std::string& prefix);

}  // namespace fresco
