#include "pipeline/core/settings.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace fresco {
namespace {

// Shortest text that reads back as the same double: 0.002, 1048576, 0.25.
std::string NumberText(double v) {
  char buffer[32];
  if (v == std::floor(v) && std::abs(v) < 1e15) {  // whole numbers in full: 80, 1048576
    std::snprintf(buffer, sizeof(buffer), "%.0f", v);
    return buffer;
  }
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof(buffer), "%.*g", digits, v);
    if (std::strtod(buffer, nullptr) == v) break;
  }
  return buffer;
}

std::string ChoiceList(const std::vector<std::string>& choices) {
  std::string text;
  for (const std::string& c : choices) text += (text.empty() ? "`" : ", `") + c + "`";
  return text;
}

}  // namespace

std::string Setting::Section() const { return key.substr(0, key.rfind('.')); }

std::string Setting::Name() const { return key.substr(key.rfind('.') + 1); }

std::string Setting::ValueText() const {
  switch (kind) {
    case Kind::kBool:
      return *flag ? "true" : "false";
    case Kind::kInt:
      return std::to_string(*integer);
    case Kind::kNumber:
      return NumberText(*number);
    case Kind::kText:
      return text->empty() ? "\"\"" : "`" + *text + "`";
    case Kind::kChoice:
      return "`" + choices[get_choice()] + "`";
  }
  return "";
}

std::string Setting::RangeText() const {
  if (kind == Kind::kBool) return "bool";
  if (kind == Kind::kChoice || (kind == Kind::kText && !choices.empty()))
    return ChoiceList(choices);
  if (kind == Kind::kText) return "text";
  const std::string type = kind == Kind::kInt ? "int " : "";
  const bool low = std::isfinite(min), high = std::isfinite(max);
  if (low && high)
    return type + (min_exclusive ? "> " : "") + NumberText(min) + " to " + NumberText(max);
  if (low) return type + (min_exclusive ? "> " : ">= ") + NumberText(min);
  if (high) return type + "<= " + NumberText(max);
  return kind == Kind::kInt ? "int" : "number";
}

std::vector<std::string> SettingsTableRows(const std::string& prefix) {
  Project defaults;
  std::vector<std::string> rows;
  for (const Setting& s : DescribeSettings(&defaults)) {
    if (s.key.compare(0, prefix.size(), prefix) != 0) continue;
    rows.push_back("| `" + s.key + "` | " + s.ValueText() + " | " + s.RangeText() + " | " + s.help +
                   " |");
  }
  return rows;
}

}  // namespace fresco
