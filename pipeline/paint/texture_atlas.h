// Texture atlas: the painted base buffers packed into a few pages (stb_rect_pack's skyline
// packer), so that a painted model has a few textures and materials, not one per buffer.
// Each buffer keeps its own texels one-to-one; around it, `padding_texels` of its edge
// texels repeated, and every placement starts on a multiple of the alignment (the padding
// rounded up to a power of two). So bilinear sampling never reads another buffer's texels,
// and neither do the first mipmap levels: a mip texel of level L covers 2^L x 2^L texels of
// one placement only while 2^L <= the alignment.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/project.h"  // AtlasOptions
#include "pipeline/core/status.h"

namespace fresco {

struct AtlasPlacement {
  int page = -1;
  int x = 0, y = 0;  // the buffer's texel (0, 0) in the page
};

struct TextureAtlas {
  std::vector<cv::Size> pages;               // each page's size (the last one cropped)
  std::vector<AtlasPlacement> placements;   // per buffer
  int padding = 0, alignment = 1;
  long long used_texels = 0;  // buffer texels (without padding) over all pages
  // Fraction of the pages' texels that hold a buffer texel.
  double Occupancy() const;
};

// The largest buffer side that fits on a page with its padding.
int MaxBufferSide(const AtlasOptions& options);

// Packs buffers of the given sizes (texels). Larger buffers first; each page is filled
// before the next opens. A buffer larger than MaxBufferSide() is an error (base buffers
// are built to fit: BaseBufferOptions::max_side_texels).
Status PackAtlas(const std::vector<cv::Size>& buffer_sizes, const AtlasOptions& options,
                 TextureAtlas* atlas);

// Page `page` as an image of `type` (e.g. CV_8UC4), each buffer image copied to its
// placement with its padding; texels of no buffer are zero.
cv::Mat ComposeAtlasPage(const TextureAtlas& atlas, int page, const std::vector<cv::Mat>& images);
// The same into `out`, whose memory is reused when it already has the page's size and type.
void ComposeAtlasPageInto(const TextureAtlas& atlas, int page, const std::vector<cv::Mat>& images,
                          cv::Mat* out);

// Buffer b's placement with its padding (b of size `buffer_size`), within its page: the
// rectangle of the page that ComposeAtlasPage fills from it.
cv::Rect PaddedPlacement(const TextureAtlas& atlas, size_t b, cv::Size buffer_size);
// Where rectangles of `sizes` go in a strip `width` wide (at least the widest): in shelves,
// the tallest first (ties in order), left to right; `strip` gets its size (at least 1 x 1).
std::vector<cv::Point> StripPositions(const std::vector<cv::Size>& sizes, int width,
                                      cv::Size* strip);
// What ComposeAtlasPage puts in the padded placements (PaddedPlacement) of the buffers
// `which` (one flag per buffer) on page `page`, without the rest of the page: those
// rectangles, in buffer order, at StripPositions in a strip as wide as the page (zero
// elsewhere). A shard's part holds its pages so (the buffers' placements never overlap).
cv::Mat ComposeAtlasStrip(const TextureAtlas& atlas, int page, const std::vector<cv::Mat>& images,
                          const std::vector<bool>& which);

}  // namespace fresco
