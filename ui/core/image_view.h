// A debug image view: the image fitted to the panel's width; the wheel zooms about the
// cursor, a drag pans, a double-click fits it again; the line under it gives the pixel under
// the cursor and its value; false-coloured images get their colour scale. ImGui only (the
// image goes through ImageTextures); the zoom maths is in zoom_pan.h.
#pragma once

#include <map>
#include <string>

#include <opencv2/core.hpp>

#include "ui/core/colour_scale.h"
#include "ui/core/panel.h"
#include "ui/core/zoom_pan.h"

namespace fresco {

// "x 12 y 40: B 10 G 20 R 30" (the channels as the image holds them: grey, BGR, BGRA or
// float); "" outside the image.
std::string DescribePixel(const cv::Mat& image, int col, int row);

class ImageView {
 public:
  // Draws `image` (texture `key`, re-uploaded when `version` changes); `scale`: its colour
  // scale when false-coloured.
  void Draw(UiContext& ui, const std::string& key, const cv::Mat& image, uint64_t version,
            const ColourScale* scale = nullptr);
  // What it shows, for Panel::Report: "zoom", "pixel" (the readout), "view" ("x y w h" of the
  // image area on screen), "legend" (the scale's ends).
  void ReportInto(std::map<std::string, std::string>* report) const;
  const ZoomPan& zoom_pan() const { return zp_; }

 private:
  ZoomPan zp_;
  cv::Size shown_;  // the image size zp_ is for (another size fits again)
  std::string readout_, legend_;
  float view_[4] = {0, 0, 0, 0};
};

}  // namespace fresco
