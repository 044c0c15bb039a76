#include "app/args.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace fresco {

std::string Args::Get(const std::string& option, const std::string& fallback) const {
  auto it = values.find(option);
  return it == values.end() || it->second.empty() ? fallback : it->second.back();
}

const std::vector<std::string>& Args::All(const std::string& option) const {
  static const std::vector<std::string> kEmpty;
  auto it = values.find(option);
  return it == values.end() ? kEmpty : it->second;
}

bool ParseArgs(const std::vector<std::string>& argv, const ArgSpec& spec, Args* args,
               std::string* error) {
  *args = Args();
  for (size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a == "--help" || a == "-h") {
      args->help = true;
      return true;
    }
    if (a.size() > 2 && a.rfind("--", 0) == 0) {
      std::string name = a, value;
      bool has_inline = false;
      if (auto eq = a.find('='); eq != std::string::npos) {
        name = a.substr(0, eq);
        value = a.substr(eq + 1);
        has_inline = true;
      }
      if (spec.switches.count(name)) {
        if (has_inline) {
          *error = name + " takes no value";
          return false;
        }
        args->switches.insert(name);
        continue;
      }
      const bool repeatable = spec.repeatable.count(name) > 0;
      if (!repeatable && !spec.options.count(name)) {
        *error = "unknown option " + name;
        return false;
      }
      if (!has_inline) {
        if (i + 1 >= argv.size()) {
          *error = name + " needs a value";
          return false;
        }
        value = argv[++i];
      }
      if (!repeatable && args->values.count(name)) {
        *error = name + " given twice";
        return false;
      }
      args->values[name].push_back(value);
      continue;
    }
    args->positional.push_back(a);
  }
  const int n = static_cast<int>(args->positional.size());
  if (n < spec.min_positional) {
    *error = "missing argument";
    return false;
  }
  if (n > spec.max_positional) {
    *error = "unexpected argument '" + args->positional[spec.max_positional] + "'";
    return false;
  }
  for (const std::string& r : spec.required) {
    if (!args->Has(r)) {
      *error = "missing " + r;
      return false;
    }
  }
  return true;
}

bool ParseDouble(const std::string& text, const std::string& what, double* value,
                 std::string* error) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno != 0 || !std::isfinite(v)) {
    *error = what + ": '" + text + "' is not a finite number";
    return false;
  }
  *value = v;
  return true;
}

bool ParseInt(const std::string& text, const std::string& what, int* value, std::string* error) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0 || v < -2147483647L || v > 2147483647L) {
    *error = what + ": '" + text + "' is not an integer";
    return false;
  }
  *value = static_cast<int>(v);
  return true;
}

}  // namespace fresco
