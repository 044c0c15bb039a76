// Why a group's texels are coarser than asked, for the Grouping panel and the status bar: a
// group whose buffer would exceed pipeline.max_buffer_texels (a merge of large surfaces,
// typically) gets larger texels (BuildBaseBuffers), which paints less detail and can lower
// the coverage. Pure logic, no ImGui.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/project.h"

namespace fresco {

struct CoarsenedGroups {
  std::vector<GroupSpec> built;             // the session's groups (one per buffer)
  std::vector<double> buffer_texel_size_m;  // (G) each buffer's texel edge as built
  double default_texel_size_m = 0;          // the session's (a group's own overrides it)
  int max_buffer_texels = 0;                // pipeline.max_buffer_texels
};

// "" when every buffer has the texels asked for; else which groups (their numbers in the
// painting, as the Grouping panel lists them) got coarser texels, by how much, and what to
// do about it.
std::string DescribeCoarsenedGroups(const CoarsenedGroups& in);

}  // namespace fresco
