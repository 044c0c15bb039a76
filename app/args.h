// A small command-line parser shared by every verb: positional arguments, `--flag VALUE`
// options (repeatable ones collect every value), boolean switches and `--help`.
// Bad usage is reported as a one-line message and exit code 2 by the caller.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

namespace fresco {

struct ArgSpec {
  std::string usage;                   // "fresco run PROJECT.json --out DIR [--set K=V ...]"
  std::string help;                    // the rest of `--help`'s text
  int min_positional = 0;
  int max_positional = 0;
  std::set<std::string> options;       // take a value: "--out"
  std::set<std::string> repeatable;    // take a value, may repeat: "--set"
  std::set<std::string> switches;      // no value: "--verbose"
  std::set<std::string> required;      // options that must be given
};

struct Args {
  std::vector<std::string> positional;
  std::map<std::string, std::vector<std::string>> values;  // option -> values in order
  std::set<std::string> switches;
  bool help = false;

  bool Has(const std::string& option) const { return values.count(option) > 0; }
  std::string Get(const std::string& option, const std::string& fallback = "") const;
  const std::vector<std::string>& All(const std::string& option) const;
  bool Switch(const std::string& name) const { return switches.count(name) > 0; }
};

// Parses argv[first..]. On bad usage fills `error` ("unknown option --x") and returns false.
bool ParseArgs(const std::vector<std::string>& argv, const ArgSpec& spec, Args* args,
               std::string* error);

// Parses a number option; on failure fills `error` naming the option.
bool ParseDouble(const std::string& text, const std::string& what, double* value,
                 std::string* error);
bool ParseInt(const std::string& text, const std::string& what, int* value, std::string* error);

}  // namespace fresco
