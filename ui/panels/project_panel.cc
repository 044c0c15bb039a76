// Project: which project is open, save / save as / open another / a new one (with the unsaved-changes
// prompt in the app frame), recent projects, undo and redo.
#include "ui/core/panel.h"  // imgui.h first: imgui_stdlib.h needs it

#include <imgui_stdlib.h>
#include "ui/panels/panels.h"

namespace fresco {
namespace {

class ProjectPanel : public Panel {
 public:
  const char* Title() const override { return "Project"; }

  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    AppState& state = *ui.state;
    if (state.has_project) {
      ImGui::TextWrapped("%s%s", state.project.file_path.c_str(), state.dirty ? "  (unsaved)" : "");
      if (ImGui::Button("Save")) Report(state, state.Save());
      ImGui::SameLine();
      FitNextItem("Save As");
      ImGui::InputTextWithHint("##saveas", "path for Save As", &save_as_);
      ImGui::SameLine();
      if (ImGui::Button("Save As") && !save_as_.empty()) Report(state, state.Save(save_as_));
    } else {
      ImGui::TextDisabled("no project open");
    }
    FitNextItem("Open");
    ImGui::InputTextWithHint("##open", "project.json to open", &open_path_);
    ImGui::SameLine();
    if (ImGui::Button("Open") && !open_path_.empty()) RequestOpen(ui, open_path_);
    if (ImGui::Button("New")) ui.new_project_requested = true;
    if (!state.recent.empty() && ImGui::TreeNode("Recent projects")) {
      for (const std::string& path : state.recent)
        if (ImGui::Selectable(path.c_str())) RequestOpen(ui, path);
      ImGui::TreePop();
    }
    ImGui::BeginDisabled(state.undo.empty());
    if (ImGui::Button("Undo")) UndoRedo(ui, true);
    ImGui::EndDisabled();
    ImGui::SameLine();
    ImGui::BeginDisabled(state.redo.empty());
    if (ImGui::Button("Redo")) UndoRedo(ui, false);
    ImGui::EndDisabled();
    SameLineIfFits(ImGui::CalcTextSize("(000 / 000 steps)").x);
    ImGui::TextDisabled("(%zu / %zu steps)", state.undo.size(), state.redo.size());
    ImGui::End();
  }

 private:
  static void Report(AppState& state, const Status& s) {
    if (!s.ok()) state.message = "error: " + s.message();
  }
  std::string open_path_, save_as_;
};

}  // namespace

std::unique_ptr<Panel> MakeProjectPanel() { return std::make_unique<ProjectPanel>(); }

}  // namespace fresco
