// Zoom and pan of an image shown in a view of a given size: the maths behind the debug image
// views (wheel zooms about the cursor, drag pans, the readout maps the cursor to a pixel).
// Pure logic, no ImGui: positions are view pixels from the view's top-left corner, image
// coordinates are pixels with (0, 0) the top-left corner of the top-left pixel.
#pragma once

namespace fresco {

struct ZoomPan {
  float zoom = 1;                      // 1 = the whole image fits the view; at most kMaxZoom
  float centre_x = -1, centre_y = -1;  // image point at the view's centre (< 0: the image's)
  static constexpr float kMaxZoom = 64;

  // View pixels per image pixel, for a view of view_w x view_h and an image of
  // image_w x image_h.
  float Scale(float view_w, float view_h, float image_w, float image_h) const;
};

struct ZoomPanView {
  float view_w = 1, view_h = 1;    // the view, pixels
  float image_w = 1, image_h = 1;  // the image, pixels
};

// Image coordinates under view position (x, y), and back.
void ViewToImage(const ZoomPan& zp, const ZoomPanView& v, float x, float y, float* ix, float* iy);
void ImageToView(const ZoomPan& zp, const ZoomPanView& v, float ix, float iy, float* x, float* y);
// Zooms by `factor` keeping the image point under (x, y) where it is (clamped to
// 1..kMaxZoom; at zoom 1 the image is centred again).
void ZoomAbout(const ZoomPan& zp, const ZoomPanView& v, float x, float y, float factor,
               ZoomPan* out);
// Moves the image with a drag of (dx, dy) view pixels; the view centre stays on the image.
void PanBy(const ZoomPan& zp, const ZoomPanView& v, float dx, float dy, ZoomPan* out);
// The pixel (column, row) under view position (x, y); false when outside the image.
bool PixelUnder(const ZoomPan& zp, const ZoomPanView& v, float x, float y, int* col, int* row);

}  // namespace fresco
