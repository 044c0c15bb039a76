// Project: which project is open, save / save as / open another / a new one (with the
// unsaved-changes prompt in the app frame), recent projects, undo and redo; and the path editor:
// the scene, video, camera and poses of the open project, or of the one that did not open because a
// file it names is missing, written back in place by "Apply and save" (checked as `fresco
// run` loads a project; every other key unchanged) and then (re)opened. Files dropped on the
// window fill its fields when the New project form is closed.
#include "ui/core/panel.h"  // imgui.h first: imgui_stdlib.h needs it

#include <imgui_stdlib.h>

#include "ui/panels/panels.h"
#include "ui/panels/path_field.h"

namespace fresco {
namespace {

class ProjectPanel : public Panel {
 public:
  const char* Title() const override { return kProjectPanelTitle; }
  std::map<std::string, std::string> Report() const override {
    return {{"scene", paths_.scene}, {"video", paths_.video},       {"camera", paths_.camera},
            {"poses", paths_.poses}, {"paths error", paths_error_}, {"paths of", shown_file_}};
  }
  bool AcceptDrop(const DroppedFile& file) override {
    std::string* field = FieldFor(file.kind, &paths_);
    if (field) *field = file.path;
    show_paths_ = show_paths_ || field;
    return field != nullptr;
  }

  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    AppState& state = *ui.state;
    if (state.has_unopened) {  // first: what the user came to fix
      DrawPaths(ui);
      // The other panels show the project still open, not this one: say so, and let the
      // user put this one aside.
      if (state.has_project)
        ImGui::TextWrapped("Every other panel still shows %s, which stays open.",
                           state.project.file_path.c_str());
      if (ImGui::Button(state.has_project ? "Keep the open project" : "Dismiss"))
        state.has_unopened = false;  // the path editor follows the open project again
      ImGui::Separator();
    }
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
    if (!state.has_unopened) DrawPaths(ui);
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
  // The path editor, over the project that did not open (first) or the open one.
  void DrawPaths(UiContext& ui) {
    AppState& state = *ui.state;
    if (!state.has_unopened && !state.has_project) return;
    const Project& target = state.has_unopened ? state.unopened : state.project;
    // The fields follow the project (opened, repaired, undone) until the user edits them.
    const ProjectPaths current = EditablePaths(target);
    if (!(current == shown_) || target.file_path != shown_file_) {
      paths_ = shown_ = current;
      shown_file_ = target.file_path;
      paths_error_.clear();
    }
    if (state.has_unopened) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.4f, 0.4f, 1.0f));
      ImGui::TextWrapped("%s did not open: fix its paths, then Apply and save.",
                         target.file_path.c_str());
      ImGui::PopStyleColor();
    }
    if (state.has_unopened || show_paths_) ImGui::SetNextItemOpen(true);
    show_paths_ = false;
    if (!ImGui::CollapsingHeader("Paths")) return;
    ProjectPathFields(&paths_, &ui.state->last_folder);
    ImGui::BeginDisabled(paths_ == shown_ && !state.has_unopened);
    if (ImGui::Button("Apply and save")) ApplyPaths(ui);
    ImGui::SameLine();
    if (ImGui::Button("Revert")) paths_ = shown_, paths_error_.clear();
    ImGui::EndDisabled();
    if (!paths_error_.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.4f, 0.4f, 1.0f));
      ImGui::TextWrapped("error: %s", paths_error_.c_str());
      ImGui::PopStyleColor();
    }
  }

  void ApplyPaths(UiContext& ui) {
    const bool reopen = !ui.state->has_unopened;
    std::string file;
    if (Status s = ui.state->RepairPaths(paths_, &file); !s.ok()) {
      paths_error_ = s.message();
      return;
    }
    paths_error_.clear();
    if (reopen)
      ReopenProject(ui);
    else
      RequestOpen(ui, file);
  }

  static void Report(AppState& state, const Status& s) {
    if (!s.ok()) state.message = "error: " + s.message();
  }
  std::string open_path_, save_as_;
  ProjectPaths paths_;       // as being edited
  ProjectPaths shown_;       // the project's when last shown (paths_ starts from them)
  std::string shown_file_;   // whose they are
  std::string paths_error_;  // the last Apply and save's
  bool show_paths_ = false;  // a drop: open the editor
};

}  // namespace

std::unique_ptr<Panel> MakeProjectPanel() { return std::make_unique<ProjectPanel>(); }

}  // namespace fresco
