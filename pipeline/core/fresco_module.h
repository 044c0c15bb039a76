// Fresco's own modules (shared objects loaded on first use, so that a process that does not
// need them never loads the libraries they bring): found in the library folder of an
// installed fresco (BINDIR/../LIBDIR/fresco), else in the build tree.
#pragma once

#include <string>

namespace fresco {

// `symbol` of the first module that loads, of `from_bindir` (relative to the running
// binary's folder) and `build_path`; null if none does (`why` says why). Loads the module,
// which stays loaded; not cached here (callers keep the symbol).
void* LoadModuleSymbol(const char* from_bindir, const char* build_path, const char* symbol,
                       std::string* why);

}  // namespace fresco
