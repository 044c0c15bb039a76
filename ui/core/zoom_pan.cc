#include "ui/core/zoom_pan.h"

#include <algorithm>
#include <cmath>

namespace fresco {
namespace {

float CentreX(const ZoomPan& zp, const ZoomPanView& v) {
  return zp.centre_x < 0 ? 0.5f * v.image_w : zp.centre_x;
}
float CentreY(const ZoomPan& zp, const ZoomPanView& v) {
  return zp.centre_y < 0 ? 0.5f * v.image_h : zp.centre_y;
}
float ScaleOf(const ZoomPan& zp, const ZoomPanView& v) {
  return zp.Scale(v.view_w, v.view_h, v.image_w, v.image_h);
}

}  // namespace

float ZoomPan::Scale(float view_w, float view_h, float image_w, float image_h) const {
  const float fit = std::min(view_w / std::max(image_w, 1.0f), view_h / std::max(image_h, 1.0f));
  return fit * zoom;
}

void ViewToImage(const ZoomPan& zp, const ZoomPanView& v, float x, float y, float* ix, float* iy) {
  const float s = ScaleOf(zp, v);
  *ix = CentreX(zp, v) + (x - 0.5f * v.view_w) / s;
  *iy = CentreY(zp, v) + (y - 0.5f * v.view_h) / s;
}

void ImageToView(const ZoomPan& zp, const ZoomPanView& v, float ix, float iy, float* x, float* y) {
  const float s = ScaleOf(zp, v);
  *x = 0.5f * v.view_w + (ix - CentreX(zp, v)) * s;
  *y = 0.5f * v.view_h + (iy - CentreY(zp, v)) * s;
}

void ZoomAbout(const ZoomPan& zp, const ZoomPanView& v, float x, float y, float factor,
               ZoomPan* out) {
  float ix = 0, iy = 0;
  ViewToImage(zp, v, x, y, &ix, &iy);
  ZoomPan next = zp;
  next.zoom = std::clamp(zp.zoom * factor, 1.0f, ZoomPan::kMaxZoom);
  if (next.zoom <= 1.0f) {
    *out = ZoomPan{};
    return;
  }
  const float s = ScaleOf(next, v);
  next.centre_x = std::clamp(ix - (x - 0.5f * v.view_w) / s, 0.0f, v.image_w);
  next.centre_y = std::clamp(iy - (y - 0.5f * v.view_h) / s, 0.0f, v.image_h);
  *out = next;
}

void PanBy(const ZoomPan& zp, const ZoomPanView& v, float dx, float dy, ZoomPan* out) {
  const float s = ScaleOf(zp, v);
  ZoomPan next = zp;
  next.centre_x = std::clamp(CentreX(zp, v) - dx / s, 0.0f, v.image_w);
  next.centre_y = std::clamp(CentreY(zp, v) - dy / s, 0.0f, v.image_h);
  *out = next;
}

bool PixelUnder(const ZoomPan& zp, const ZoomPanView& v, float x, float y, int* col, int* row) {
  float ix = 0, iy = 0;
  ViewToImage(zp, v, x, y, &ix, &iy);
  if (ix < 0 || iy < 0 || ix >= v.image_w || iy >= v.image_h) return false;
  *col = static_cast<int>(std::floor(ix));
  *row = static_cast<int>(std::floor(iy));
  return true;
}

}  // namespace fresco
