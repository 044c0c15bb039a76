// libFuzzer target: the project file (ParseProject). Bytes after a NUL are `--set KEY=VALUE`
// overrides (one per NUL-separated part). Whatever parses must save and parse back to the
// same project (docs/contract.md: loading what was saved gives back the same project).
#include <string>
#include <vector>

#include "pipeline/core/project.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input = fresco::fuzz::AsText(data, size);
  const size_t nul = input.find('\0');
  const std::string text = input.substr(0, nul);
  std::vector<std::string> overrides;
  for (size_t start = nul; start != std::string::npos && start < input.size();) {
    const size_t end = input.find('\0', start + 1);
    overrides.push_back(input.substr(start + 1, end == std::string::npos ? end : end - start - 1));
    start = end;
  }
  const std::string name = "/fuzz/project.json";
  fresco::Project project;
  if (!fresco::ParseProject(text, name, overrides, &project).ok()) return 0;
  fresco::Project again;
  const fresco::Status status =
      fresco::ParseProject(fresco::ProjectToJsonText(project), name, {}, &again);
  FUZZ_CHECK(status.ok());
  FUZZ_CHECK(again == project);
  (void)project.Resolve(project.scene);
  return 0;
}
