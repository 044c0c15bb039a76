#include "pipeline/paint/texture_atlas.h"

#include <algorithm>
#include <string>
#include <utility>

#include <opencv2/core.hpp>
#include <stb/stb_rect_pack.h>  // implementation in Debian's libstb

namespace fresco {
namespace {

int AlignmentFor(int padding) {
  int a = 1;
  while (a < padding) a *= 2;
  return a;
}

int AlignUp(int v, int a) { return (v + a - 1) / a * a; }

}  // namespace

double TextureAtlas::Occupancy() const {
  long long total = 0;
  for (const cv::Size& s : pages) total += static_cast<long long>(s.width) * s.height;
  return total > 0 ? static_cast<double>(used_texels) / total : 0.0;
}

int MaxBufferSide(const AtlasOptions& options) {
  const int align = AlignmentFor(options.padding_texels);
  // The placement (buffer + padding on both sides, rounded up) must fit on the page.
  return (options.page_size / align) * align - 2 * options.padding_texels;
}

Status PackAtlas(const std::vector<cv::Size>& buffer_sizes, const AtlasOptions& options,
                 TextureAtlas* atlas) {
  *atlas = TextureAtlas();
  atlas->padding = options.padding_texels;
  atlas->alignment = AlignmentFor(options.padding_texels);
  atlas->placements.assign(buffer_sizes.size(), AtlasPlacement());
  const int pad = atlas->padding, align = atlas->alignment;
  const int max_side = MaxBufferSide(options);
  std::vector<stbrp_rect> pending;
  pending.reserve(buffer_sizes.size());
  for (size_t b = 0; b < buffer_sizes.size(); ++b) {
    const cv::Size s = buffer_sizes[b];
    if (s.width > max_side || s.height > max_side)
      return Status::Error("base buffer " + std::to_string(b) + " is " + std::to_string(s.width) +
                           "x" + std::to_string(s.height) + " texels: larger than an atlas page of " +
                           std::to_string(options.page_size) + " holds (pipeline.atlas.page_size)");
    if (s.width <= 0 || s.height <= 0) continue;  // nothing to place
    stbrp_rect r{};
    r.id = static_cast<int>(b);
    r.w = AlignUp(s.width + 2 * pad, align);
    r.h = AlignUp(s.height + 2 * pad, align);
    pending.push_back(r);
    atlas->used_texels += static_cast<long long>(s.width) * s.height;
  }
  // Packing in units of the alignment keeps every placement aligned.
  const int cells = options.page_size / align;
  std::vector<stbrp_node> nodes(cells);
  while (!pending.empty()) {
    for (stbrp_rect& r : pending) r.w /= align, r.h /= align;
    stbrp_context context;
    stbrp_init_target(&context, cells, cells, nodes.data(), static_cast<int>(nodes.size()));
    stbrp_setup_heuristic(&context, STBRP_HEURISTIC_Skyline_BL_sortHeight);
    stbrp_pack_rects(&context, pending.data(), static_cast<int>(pending.size()));
    const int page = static_cast<int>(atlas->pages.size());
    int used_w = 0, used_h = 0;
    std::vector<stbrp_rect> rest;
    for (stbrp_rect r : pending) {
      r.w *= align, r.h *= align;
      if (!r.was_packed) {
        rest.push_back(r);
        continue;
      }
      AtlasPlacement& p = atlas->placements[r.id];
      p.page = page;
      p.x = r.x * align + pad;
      p.y = r.y * align + pad;
      used_w = std::max(used_w, r.x * align + r.w);
      used_h = std::max(used_h, r.y * align + r.h);
    }
    if (used_w == 0)  // cannot happen: every rect fits an empty page
      return Status::Error("texture atlas: a buffer does not fit an empty page");
    atlas->pages.emplace_back(used_w, used_h);
    pending.swap(rest);
  }
  return Status::Ok();
}

cv::Mat ComposeAtlasPage(const TextureAtlas& atlas, int page, const std::vector<cv::Mat>& images) {
  cv::Mat out;
  ComposeAtlasPageInto(atlas, page, images, &out);
  return out;
}

namespace {

// The images' type (an empty image, a buffer left out, says nothing of it; none: CV_8UC4).
int ImagesType(const std::vector<cv::Mat>& images) {
  for (const cv::Mat& image : images)
    if (!image.empty()) return image.type();
  return CV_8UC4;
}

}  // namespace

cv::Rect PaddedPlacement(const TextureAtlas& atlas, size_t b, cv::Size buffer_size) {
  const AtlasPlacement& p = atlas.placements[b];
  if (p.page < 0) return cv::Rect();
  const int pad = atlas.padding;
  return cv::Rect(p.x - pad, p.y - pad, buffer_size.width + 2 * pad, buffer_size.height + 2 * pad) &
         cv::Rect(cv::Point(0, 0), atlas.pages[p.page]);
}

std::vector<cv::Point> StripPositions(const std::vector<cv::Size>& sizes, int width,
                                      cv::Size* strip) {
  for (const cv::Size& size : sizes) width = std::max(width, size.width);
  std::vector<size_t> order(sizes.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return sizes[a].height > sizes[b].height; });
  std::vector<cv::Point> at(sizes.size());
  int x = 0, y = 0, shelf = 0;  // the shelf's top is y, its height the first (tallest) one's
  for (size_t k : order) {
    if (x + sizes[k].width > width) y += shelf, x = 0, shelf = 0;
    at[k] = cv::Point(x, y);
    x += sizes[k].width;
    shelf = std::max(shelf, sizes[k].height);
  }
  *strip = cv::Size(std::max(width, 1), std::max(y + shelf, 1));
  return at;
}

cv::Mat ComposeAtlasStrip(const TextureAtlas& atlas, int page, const std::vector<cv::Mat>& images,
                          const std::vector<bool>& which) {
  std::vector<size_t> buffers;
  std::vector<cv::Size> sizes;
  for (size_t b = 0; b < images.size() && b < atlas.placements.size() && b < which.size(); ++b) {
    if (!which[b] || atlas.placements[b].page != page) continue;
    buffers.push_back(b);
    sizes.push_back(PaddedPlacement(atlas, b, images[b].size()).size());
  }
  cv::Size strip;
  const std::vector<cv::Point> at = StripPositions(sizes, atlas.pages[page].width, &strip);
  cv::Mat out = cv::Mat::zeros(strip, ImagesType(images));
  const int pad = atlas.padding;
  for (size_t k = 0; k < buffers.size(); ++k) {
    const cv::Mat& image = images[buffers[k]];
    const AtlasPlacement& p = atlas.placements[buffers[k]];
    if (image.empty()) continue;
    const cv::Rect rect = PaddedPlacement(atlas, buffers[k], image.size());
    cv::Mat padded;
    cv::copyMakeBorder(image, padded, pad, pad, pad, pad, cv::BORDER_REPLICATE);
    // The padded image's texel at the rectangle's corner (the page may clip it).
    const cv::Point from(rect.x - (p.x - pad), rect.y - (p.y - pad));
    padded(cv::Rect(from, rect.size())).copyTo(out(cv::Rect(at[k], rect.size())));
  }
  return out;
}

void ComposeAtlasPageInto(const TextureAtlas& atlas, int page, const std::vector<cv::Mat>& images,
                          cv::Mat* page_image) {
  const int type = ImagesType(images);
  page_image->create(atlas.pages[page], type);
  page_image->setTo(cv::Scalar::all(0));
  cv::Mat& out = *page_image;
  const int pad = atlas.padding;
  for (size_t b = 0; b < images.size() && b < atlas.placements.size(); ++b) {
    const AtlasPlacement& p = atlas.placements[b];
    const cv::Mat& image = images[b];
    if (p.page != page || image.empty()) continue;
    const cv::Rect with_padding(p.x - pad, p.y - pad, image.cols + 2 * pad, image.rows + 2 * pad);
    cv::copyMakeBorder(image, out(with_padding), pad, pad, pad, pad, cv::BORDER_REPLICATE);
  }
}

}  // namespace fresco
