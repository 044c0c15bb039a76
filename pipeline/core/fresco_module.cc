#include "pipeline/core/fresco_module.h"

#include <filesystem>
#include <vector>

#include <dlfcn.h>

namespace fresco {

void* LoadModuleSymbol(const char* from_bindir, const char* build_path, const char* symbol,
                       std::string* why) {
  namespace fs = std::filesystem;
  std::vector<std::string> paths;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) paths.push_back((self.parent_path() / from_bindir).lexically_normal());
  paths.push_back(build_path);
  for (const std::string& path : paths) {
    void* module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!module) {
      const char* message = dlerror();
      *why = message ? message : path + ": cannot load";
      continue;
    }
    if (void* found = dlsym(module, symbol)) return found;
    *why = path + ": no " + symbol;
  }
  return nullptr;
}

}  // namespace fresco
