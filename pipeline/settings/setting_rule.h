// What a project-file field accepts beyond its type, and what it does: the rule each
// `Fields(struct, visitor)` list gives its fields (project.cc reads and writes by it; the
// settings' ranges and help come from it).
#pragma once

#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace fresco {

// What a field accepts beyond its type. Numbers: [min, max] (min exclusive when asked);
// strings: non-empty, or one of `choices`.
struct Rule {
  bool required = false;
  bool non_empty = false;
  double min = -std::numeric_limits<double>::infinity();
  bool min_exclusive = false;
  double max = std::numeric_limits<double>::infinity();
  std::vector<std::string> choices = {};
  const char* help = "";  // what the setting does (fresco settings, the app, the docs)
};

// An enum's names in the project file, in order.
template <class E>
using EnumNames = std::vector<std::pair<E, std::string>>;

}  // namespace fresco
