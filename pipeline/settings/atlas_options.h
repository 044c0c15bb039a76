// The texture atlas stage's settings: the struct the stage reads, and its fields as the project
// file, `--set`, `fresco settings`, the app's settings widgets and the docs' settings table
// see them (each with its range and help, listed once in Fields). Adding a setting is a member
// here and its line in Fields; nothing else.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "pipeline/settings/setting_rule.h"

namespace fresco {

// The painted model's texture atlas (pipeline/paint/texture_atlas.h): base buffers packed
// into pages of at most page_size x page_size texels, each with padding_texels of its edge
// repeated around it.
struct AtlasOptions {
  int page_size = 4096;
  int padding_texels = 4;

  bool operator==(const AtlasOptions&) const = default;
};

template <class V>
void Fields(AtlasOptions& o, V& v) {
  v.Field("page_size", o.page_size,
          {.min = 256,
           .max = 8192,
           .help = "charts are packed into texture pages of at most this size (8192 is what "
                   "viewers and GPUs take)"});
  v.Field("padding_texels", o.padding_texels,
          {.min = 0,
           .max = 32,
           .help = "edge texels repeated around each chart, so bilinear sampling and the first "
                   "mipmap levels never mix two charts"});
}

}  // namespace fresco
