#include "ui/core/texel_cap_note.h"

#include <cstdio>

namespace fresco {

std::string DescribeCoarsenedGroups(const CoarsenedGroups& in) {
  std::string list;
  int coarsened = 0;
  for (size_t g = 0; g < in.built.size() && g < in.buffer_texel_size_m.size(); ++g) {
    const double asked =
        in.built[g].texel_size_m > 0 ? in.built[g].texel_size_m : in.default_texel_size_m;
    const double built = in.buffer_texel_size_m[g];
    if (asked <= 0 || built <= asked * 1.001) continue;
    ++coarsened;
    if (coarsened > 3) continue;  // the first few name it
    char item[160];
    std::snprintf(item, sizeof(item), "%sgroup %zu: %.4g m instead of %.4g m (%.1fx coarser)",
                  list.empty() ? "" : ", ", g, built, asked, built / asked);
    list += item;
  }
  if (coarsened == 0) return "";
  if (coarsened > 3) list += ", ...";
  return "coarser texels: " + std::to_string(coarsened) + " group" + (coarsened > 1 ? "s" : "") +
         " would exceed the " + std::to_string(in.max_buffer_texels) +
         " texels a buffer may hold, so " + (coarsened > 1 ? "their" : "its") +
         " texels were enlarged (" + list +
         "): less detail and possibly less coverage; split the group, set a larger texel size "
         "for it, or raise max_buffer_texels";
}

}  // namespace fresco
