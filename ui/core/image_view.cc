#include "ui/core/image_view.h"

#include <cmath>
#include <cstdio>

#include <imgui_internal.h>
#include <opencv2/imgproc.hpp>

namespace fresco {
namespace {

void DrawLegend(const ColourScale& scale) {
  static_assert(sizeof(ImU32) == 4);
  cv::Mat ramp(1, 256, CV_8UC1), colours;
  for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(0, i) = static_cast<uint8_t>(i);
  cv::applyColorMap(ramp, colours, scale.colormap);
  // The bar across the panel, what its two ends mean under them.
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  const float width = std::max(32.0f, ImGui::GetContentRegionAvail().x);
  const float height = ImGui::GetTextLineHeight();
  ImDrawList* draw = ImGui::GetWindowDrawList();
  constexpr int kSteps = 32;
  for (int s = 0; s < kSteps; ++s) {
    const cv::Vec3b bgr = colours.at<cv::Vec3b>(0, s * 255 / (kSteps - 1));
    const float x0 = origin.x + width * s / kSteps, x1 = origin.x + width * (s + 1) / kSteps;
    draw->AddRectFilled(ImVec2(x0, origin.y), ImVec2(x1, origin.y + height),
                        IM_COL32(bgr[2], bgr[1], bgr[0], 255));
  }
  ImGui::Dummy(ImVec2(width, height));
  ImGui::TextUnformatted(scale.low.c_str());
  const float high = ImGui::CalcTextSize(scale.high.c_str()).x;
  SameLineIfFits(high);
  ImGui::SetCursorPosX(
      std::max(ImGui::GetCursorPosX(), ImGui::GetWindowContentRegionMax().x - high));
  ImGui::TextUnformatted(scale.high.c_str());
}

}  // namespace

std::string DescribePixel(const cv::Mat& image, int col, int row) {
  if (col < 0 || row < 0 || col >= image.cols || row >= image.rows) return "";
  char text[160];
  int n = std::snprintf(text, sizeof(text), "x %d y %d:", col, row);
  auto add = [&](const char* name, double value, bool integer) {
    if (n < 0 || n >= static_cast<int>(sizeof(text))) return;
    n += integer ? std::snprintf(text + n, sizeof(text) - n, " %s%.0f", name, value)
                 : std::snprintf(text + n, sizeof(text) - n, " %s%.4g", name, value);
  };
  const int channels = image.channels();
  const char* names3[] = {"B ", "G ", "R ", "A "};
  for (int c = 0; c < channels && c < 4; ++c) {
    const char* name = channels == 1 ? "" : names3[c];
    switch (image.depth()) {
      case CV_8U:
        add(name, image.ptr<uint8_t>(row)[col * channels + c], true);
        break;
      case CV_16U:
        add(name, image.ptr<uint16_t>(row)[col * channels + c], true);
        break;
      case CV_32S:
        add(name, image.ptr<int32_t>(row)[col * channels + c], true);
        break;
      case CV_32F:
        add(name, image.ptr<float>(row)[col * channels + c], false);
        break;
      case CV_64F:
        add(name, image.ptr<double>(row)[col * channels + c], false);
        break;
      default:
        break;
    }
  }
  return text;
}

void ImageView::Draw(UiContext& ui, const std::string& key, const cv::Mat& image, uint64_t version,
                     const ColourScale* scale) {
  readout_.clear();
  legend_ = scale ? scale->low + " .. " + scale->high : "";
  if (image.empty()) {
    ImGui::TextDisabled("(no image)");
    return;
  }
  if (image.size() != shown_) {  // another image: fit it
    zp_ = ZoomPan{};
    shown_ = image.size();
  }
  // Room for a vertical scroll bar whether or not there is one: an image whose height
  // follows its width would otherwise make the scroll bar come and go every frame.
  const bool scrollbar = ImGui::GetCurrentWindow()->ScrollbarY;
  // The whole image in view where the panel is tall enough (a maximised panel), leaving
  // room for the readout and legend lines under it.
  const float aspect = static_cast<float>(image.rows) / std::max(1, image.cols);
  // (Window height less where the image starts in the content: the same however scrolled.)
  const float room_y = ImGui::GetWindowHeight() - ImGui::GetCursorPosY() -
                       ImGui::GetStyle().WindowPadding.y - 3 * ImGui::GetFrameHeightWithSpacing();
  const float width =
      std::max(16.0f, std::min(ImGui::GetContentRegionAvail().x -
                                   (scrollbar ? 0.0f : ImGui::GetStyle().ScrollbarSize),
                               std::max(8 * ImGui::GetFontSize(), room_y) / aspect));
  const float height = width * aspect;
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  // The view captures the mouse: a drag pans the image and never moves the window.
  ImGui::InvisibleButton("##image_view", ImVec2(width, height),
                         ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight);
  const ZoomPanView v{width, height, static_cast<float>(image.cols),
                      static_cast<float>(image.rows)};
  const ImGuiIO& io = ImGui::GetIO();
  const float mx = io.MousePos.x - origin.x, my = io.MousePos.y - origin.y;
  if (ImGui::IsItemHovered() && io.MouseWheel != 0)
    ZoomAbout(zp_, v, mx, my, std::pow(1.25f, io.MouseWheel), &zp_);
  if (ImGui::IsItemActive() && (io.MouseDelta.x != 0 || io.MouseDelta.y != 0) &&
      io.MouseDelta.x > -1e6f)
    PanBy(zp_, v, io.MouseDelta.x, io.MouseDelta.y, &zp_);
  if (ImGui::IsItemHovered() && ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left)) zp_ = ZoomPan{};
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  ImageToView(zp_, v, 0, 0, &x0, &y0);
  ImageToView(zp_, v, static_cast<float>(image.cols), static_cast<float>(image.rows), &x1, &y1);
  ImDrawList* draw = ImGui::GetWindowDrawList();
  draw->PushClipRect(origin, ImVec2(origin.x + width, origin.y + height), true);
  draw->AddImage(ui.textures->Get(key, image, version), ImVec2(origin.x + x0, origin.y + y0),
                 ImVec2(origin.x + x1, origin.y + y1));
  draw->PopClipRect();
  view_[0] = origin.x, view_[1] = origin.y, view_[2] = width, view_[3] = height;
  int col = -1, row = -1;
  if (ImGui::IsItemHovered() && PixelUnder(zp_, v, mx, my, &col, &row))
    readout_ = DescribePixel(image, col, row);
  if (ImGui::IsItemHovered() && readout_.empty())
    ImGui::SetTooltip("wheel zooms, drag pans, double-click fits");
  if (!readout_.empty())
    ImGui::TextWrapped("%s", readout_.c_str());
  else
    ImGui::TextDisabled("%d x %d, zoom %.1fx", image.cols, image.rows, zp_.zoom);
  if (scale) DrawLegend(*scale);
}

void ImageView::ReportInto(std::map<std::string, std::string>* report) const {
  char text[96];
  std::snprintf(text, sizeof(text), "%.3f", zp_.zoom);
  (*report)["zoom"] = text;
  (*report)["pixel"] = readout_;
  std::snprintf(text, sizeof(text), "%.3f %.3f %.3f %.3f", view_[0], view_[1], view_[2], view_[3]);
  (*report)["view"] = text;
  if (!legend_.empty()) (*report)["legend"] = legend_;
}

}  // namespace fresco
