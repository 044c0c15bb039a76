#include "pipeline/eval/eval_suite.h"

#include <algorithm>
#include <filesystem>
#include <set>

#include <nlohmann/json.hpp>

#include "pipeline/core/atomic_file.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

bool ValidName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
  }) && name[0] != '.';
}

Status ReadCapture(const json& entry, const json& defaults, const std::string& where,
                   std::vector<SuiteCapture>* out) {
  if (!entry.is_object()) return Status::Error(where + ": must be an object");
  for (const auto& [key, value] : entry.items()) {
    if (key != "name" && key != "family" && key != "synth" && key != "seeds")
      return Status::Error(where + "." + key + ": unknown key (name, family, synth, seeds)");
  }
  SuiteCapture c;
  if (!entry.contains("name") || !entry["name"].is_string() ||
      !ValidName(entry["name"].get<std::string>()))
    return Status::Error(where + ".name: missing, or not a name of letters, digits, . _ -");
  c.name = entry["name"].get<std::string>();
  if (!entry.contains("family") || !entry["family"].is_string() ||
      !ValidName(entry["family"].get<std::string>()))
    return Status::Error(where + ".family: missing, or not a name of letters, digits, . _ -");
  c.family = entry["family"].get<std::string>();
  if (!entry.contains("synth") || !entry["synth"].is_object())
    return Status::Error(where + ".synth: missing, or not a synth spec object");
  if (entry["synth"].contains("out"))
    return Status::Error(where + ".synth.out: not allowed (the cache folder is the output)");
  json spec = defaults;
  spec.merge_patch(entry["synth"]);
  c.spec_name = where + ".synth";
  if (!entry.contains("seeds")) {
    c.spec_text = spec.dump();
    out->push_back(std::move(c));
    return Status::Ok();
  }
  const json& seeds = entry["seeds"];
  if (!seeds.is_array() || seeds.empty())
    return Status::Error(where + ".seeds: must be a non-empty array of seeds");
  for (size_t k = 0; k < seeds.size(); ++k) {
    if (!seeds[k].is_number_unsigned())
      return Status::Error(where + ".seeds[" + std::to_string(k) +
                           "]: must be an unsigned integer");
    SuiteCapture seeded = c;
    const unsigned seed = seeds[k].get<unsigned>();
    seeded.name = c.name + "-s" + std::to_string(seed);
    spec["seed"] = seed;
    seeded.spec_text = spec.dump();
    seeded.spec_name = where + ".synth (seed " + std::to_string(seed) + ")";
    out->push_back(std::move(seeded));
  }
  return Status::Ok();
}

}  // namespace

Status LoadEvalSuite(const std::string& path, EvalSuite* suite) {
  if (!fs::is_regular_file(path)) return Status::Error(path + ": no such file");
  std::string text;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &text));
  const json root = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (root.is_discarded()) return Status::Error(path + ": not valid JSON");
  if (!root.is_object()) return Status::Error(path + ": must be a JSON object");
  for (const auto& [key, value] : root.items()) {
    if (key != "fresco_eval_suite" && key != "defaults" && key != "captures")
      return Status::Error(path + ": " + key +
                           ": unknown key (fresco_eval_suite, defaults, captures)");
  }
  if (root.contains("fresco_eval_suite") && root["fresco_eval_suite"] != 1)
    return Status::Error(path + ": fresco_eval_suite: unsupported version (1 expected)");
  json defaults = json::object();
  if (root.contains("defaults")) {
    defaults = root["defaults"];
    if (!defaults.is_object()) return Status::Error(path + ": defaults: must be an object");
  }
  if (!root.contains("captures") || !root["captures"].is_array() || root["captures"].empty())
    return Status::Error(path + ": captures: missing or empty");
  suite->path = path;
  suite->base_dir = fs::absolute(path).parent_path().string();
  suite->captures.clear();
  const json& captures = root["captures"];
  for (size_t i = 0; i < captures.size(); ++i) {
    FRESCO_RETURN_IF_ERROR(ReadCapture(
        captures[i], defaults, path + ": captures[" + std::to_string(i) + "]", &suite->captures));
  }
  std::set<std::string> names;
  for (const SuiteCapture& c : suite->captures) {
    if (!names.insert(c.name).second)
      return Status::Error(c.spec_name + ": name '" + c.name + "' is used twice");
    SynthJob job;
    FRESCO_RETURN_IF_ERROR(BuildSuiteCaptureJob(*suite, c, &job));
    if (!job.streams.empty()) {
      return Status::Error(c.spec_name +
                           ": streams: the evaluation suite scores one-camera captures");
    }
  }
  return Status::Ok();
}

Status BuildSuiteCaptureJob(const EvalSuite& suite, const SuiteCapture& capture, SynthJob* job) {
  SynthSpecInput input;
  input.text = capture.spec_text;
  input.name = capture.spec_name;
  input.base_dir = suite.base_dir;
  return BuildSynthJob(input, job);
}

Status SelectSuiteCaptures(const std::vector<std::string>& names, EvalSuite* suite) {
  if (names.empty()) return Status::Ok();
  std::vector<SuiteCapture> kept;
  for (const std::string& name : names) {
    for (const SuiteCapture& c : suite->captures) {
      if ((c.name == name || c.family == name) &&
          std::none_of(kept.begin(), kept.end(),
                       [&](const SuiteCapture& k) { return k.name == c.name; }))
        kept.push_back(c);
    }
    const bool known =
        std::any_of(suite->captures.begin(), suite->captures.end(),
                    [&](const SuiteCapture& c) { return c.name == name || c.family == name; });
    if (!known)
      return Status::Error(suite->path + ": --only: no capture or family named '" + name + "'");
  }
  suite->captures = std::move(kept);
  return Status::Ok();
}

}  // namespace fresco
