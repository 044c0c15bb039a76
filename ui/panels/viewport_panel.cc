// 3D view: the model with its live painted textures, the base-buffer groups in distinct
// colours, or the current frame projected onto the model; the current camera's frustum and
// the path. Drag to orbit, right-drag to pan, wheel to zoom, click to pick a triangle
// (shift-click adds to the selection; ctrl-click selects its group) for the grouping editor.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "ui/core/panel.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

class ViewportPanel : public Panel {
 public:
  const char* Title() const override { return "3D view"; }

  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    int mode = static_cast<int>(view_.mode);
    ImGui::RadioButton("painted", &mode, 0);
    ImGui::SameLine();
    ImGui::RadioButton("groups", &mode, 1);
    ImGui::SameLine();
    ImGui::RadioButton("frame projected", &mode, 2);
    view_.mode = static_cast<ViewportView::Mode>(mode);
    ImGui::Checkbox("path", &view_.show_path);
    ImGui::SameLine();
    ImGui::Checkbox("frustum", &view_.show_frustum);
    ImGui::SameLine();
    if (ui.snapshot->layers && !ui.snapshot->layers->empty()) {
      ImGui::Checkbox("layers", &view_.view_layers);
      if (ImGui::IsItemHovered())
        ImGui::SetTooltip(
            "painted mode: the view-dependent layers (pipeline.layers) whose frames were taken "
            "nearest the viewer, blended per pixel (among the four nearest each chart's centre); "
            "off: the single texture");
      ImGui::SameLine();
    }
    FillPoseCheck(ui);
    if (!view_.pose_check.empty()) {
      ImGui::Checkbox("COLMAP path", &view_.show_pose_check);
      if (ImGui::IsItemHovered())
        ImGui::SetTooltip(
            "the last pose verification (Poses panel): COLMAP's camera centres aligned to the "
            "given poses (orange), each flagged frame's offset from its given centre (red)");
      ImGui::SameLine();
    }
    if (ImGui::SmallButton("reset view")) {
      const ViewportView::Mode mode = view_.mode;
      const bool show_pose_check = view_.show_pose_check;
      view_ = ViewportView();
      view_.mode = mode;
      view_.show_pose_check = show_pose_check;
    }

    const ImVec2 avail = ImGui::GetContentRegionAvail();
    const int w = std::max(16, static_cast<int>(avail.x)),
              h = std::max(16, static_cast<int>(avail.y));
    if (!ui.viewport || !ui.snapshot->geometry) {
      ImGui::TextDisabled("no model");
      ImGui::End();
      return;
    }
    const ImTextureID image = ui.viewport->Render(*ui.snapshot, *ui.state, &view_, w, h);
    const ImVec2 origin = ImGui::GetCursorScreenPos();
    const ImVec2 size(static_cast<float>(w), static_cast<float>(h));
    // The view captures the mouse (an invisible button under the image): a drag orbits and
    // never moves the window, and keeps orbiting when the cursor leaves the view.
    ImGui::InvisibleButton("##view", size,
                           ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight |
                               ImGuiButtonFlags_MouseButtonMiddle);
    // The offscreen image is bottom-up (OpenGL): flip it.
    ImGui::GetWindowDrawList()->AddImage(
        image, origin, ImVec2(origin.x + size.x, origin.y + size.y), ImVec2(0, 1), ImVec2(1, 0));
    HandleMouse(ui, origin, w, h);
    ImGui::End();
  }

  std::map<std::string, std::string> Report() const override {
    char text[64];
    std::snprintf(text, sizeof(text), "%.2f %.2f %.4f", view_.yaw_deg, view_.pitch_deg,
                  view_.distance_m);
    return {{"yaw pitch distance", text},
            {"COLMAP path frames", std::to_string(view_.pose_check.size())}};
  }

 private:
  // The marks of the Poses panel's last verification (none before one, or for another
  // project's run).
  void FillPoseCheck(UiContext& ui) {
    if (!ui.poses) return;
    const std::shared_ptr<const PosesSnapshot> poses = ui.poses->Snapshot();
    const std::string& project = ui.state->project.file_path;
    if (poses->version == pose_check_version_ && project == pose_check_project_) return;
    pose_check_version_ = poses->version;
    pose_check_project_ = project;
    view_.pose_check.clear();
    if (!poses->verified || poses->request.project.file_path != project) return;
    for (const FrameVerdict& f : poses->verify.frames)
      if (f.registered && f.has_given)
        view_.pose_check.push_back({f.given_centre_m, f.colmap_centre_m, f.flagged});
  }
  uint64_t pose_check_version_ = 0;
  std::string pose_check_project_;

  void HandleMouse(UiContext& ui, ImVec2 origin, int w, int h) {
    const bool active = ImGui::IsItemActive();
    if (!ImGui::IsItemHovered() && !active) return;
    ImGuiIO& io = ImGui::GetIO();
    if (active && ImGui::IsMouseDragging(ImGuiMouseButton_Left)) {
      view_.yaw_deg -= io.MouseDelta.x * 0.4f;
      view_.pitch_deg = std::clamp(view_.pitch_deg + io.MouseDelta.y * 0.4f, -89.0f, 89.0f);
    }
    if (active && (ImGui::IsMouseDragging(ImGuiMouseButton_Right) ||
                   ImGui::IsMouseDragging(ImGuiMouseButton_Middle))) {
      // Pan in the view plane, by the distance so a texel-sized drag stays texel-sized.
      const float yaw = view_.yaw_deg * static_cast<float>(M_PI) / 180,
                  pitch = view_.pitch_deg * static_cast<float>(M_PI) / 180;
      const float scale = std::max(view_.distance_m, 0.1f) / h;
      const Eigen::Vector3f right = OrbitScreenRight(view_.orbit, yaw);
      const Eigen::Vector3f up = OrbitScreenUp(view_.orbit, yaw, pitch);
      for (int k = 0; k < 3; ++k)
        view_.target[k] += (-io.MouseDelta.x * right[k] + io.MouseDelta.y * up[k]) * scale;
    }
    if (ImGui::IsItemHovered() && io.MouseWheel != 0)
      view_.distance_m *= std::pow(0.9f, io.MouseWheel);
    if (ImGui::IsItemHovered() && ImGui::IsMouseReleased(ImGuiMouseButton_Left) && !dragged_) {
      const int x = static_cast<int>(io.MousePos.x - origin.x);
      const int y = h - 1 - static_cast<int>(io.MousePos.y - origin.y);  // GL rows go up
      const int triangle = ui.viewport->Pick(x, y);
      AppState& state = *ui.state;
      const auto& of = ui.snapshot->geometry->buffer_of_triangle;
      const int group = triangle >= 0 && triangle < static_cast<int>(of.size()) ? of[triangle] : -1;
      if (io.KeyCtrl) {  // ctrl-click: the triangle's group, for merging and texel sizes
        if (group >= 0) state.selected_groups.insert(group);
      } else {
        if (!io.KeyShift) state.selected_triangles.clear();
        if (triangle >= 0) state.selected_triangles.insert(triangle);
      }
      if (triangle >= 0)
        state.message = "picked triangle " + std::to_string(triangle) + " (group " +
                        std::to_string(group) + ")";
    }
    dragged_ = ImGui::IsMouseDragging(ImGuiMouseButton_Left, 2.0f);
    (void)w;
  }

  ViewportView view_;
  bool dragged_ = false;
};

}  // namespace

std::unique_ptr<Panel> MakeViewportPanel() { return std::make_unique<ViewportPanel>(); }

}  // namespace fresco
