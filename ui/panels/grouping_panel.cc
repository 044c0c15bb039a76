// Grouping editor (paper §3.6): the automatic grouping's angle and texel size with live
// re-grouping; the groups the session built (one per base buffer); merge, split, move
// triangles and per-group texel size on the selection (groups here, triangles picked in the
// 3D view); all undoable, stored in the project as explicit groups and honoured by
// `fresco run`.
#include <algorithm>
#include <cstdio>

#include <imgui_internal.h>  // TableSetColumnWidthAutoAll

#include "ui/core/group_colour.h"
#include "ui/core/panel.h"
#include "ui/core/texel_cap_note.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

class GroupingPanel : public Panel {
 public:
  const char* Title() const override { return "Grouping"; }

  void Draw(UiContext& ui) override {
    if (!BeginPanel(*this)) {
      ImGui::End();
      return;
    }
    AppState& state = *ui.state;
    const RunnerSnapshot& snap = *ui.snapshot;
    if (!state.has_project || !snap.geometry) {
      ImGui::TextDisabled("no project painting");
      ImGui::End();
      return;
    }
    const SessionGeometry& geo = *snap.geometry;
    const int num_triangles = static_cast<int>(geo.buffer_of_triangle.size());
    const bool explicit_groups = !state.project.grouping.groups.empty();
    if (snap.geometry_version != checked_geometry_) {  // a new session: did a merge hold?
      checked_geometry_ = snap.geometry_version;
      split_message_ = explicit_groups ? DescribeGroupsSplitBack(state.project.grouping.groups,
                                                                 geo.groups, num_triangles)
                                       : "";
      coarse_message_ =
          DescribeCoarsenedGroups({geo.groups, geo.buffer_texel_size_m, geo.texel_size_m,
                                   state.project.pipeline.max_buffer_texels});
      // After an edit (stored groups) the status bar says what the painting made of it.
      std::string said = split_message_;
      if (explicit_groups && !coarse_message_.empty())
        said += (said.empty() ? "" : "; ") + coarse_message_;
      if (!said.empty()) state.message = "grouping: " + said;
      colours_.clear();
      for (const GroupSpec& g : geo.groups) {
        const auto rgb = GroupColour(StableGroupKey(g));
        char hex[8];
        std::snprintf(hex, sizeof(hex), "#%02x%02x%02x", static_cast<int>(rgb[0] * 255 + 0.5f),
                      static_cast<int>(rgb[1] * 255 + 0.5f), static_cast<int>(rgb[2] * 255 + 0.5f));
        if (!colours_.empty()) colours_ += ' ';
        colours_.append(std::to_string(StableGroupKey(g))).append(hex);
      }
    }
    if (!split_message_.empty())
      ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "%s", "Grouping changed when painting:");
    if (!split_message_.empty()) ImGui::TextWrapped("%s", split_message_.c_str());
    if (!coarse_message_.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.75f, 0.3f, 1.0f));
      ImGui::TextWrapped("%s", coarse_message_.c_str());
      ImGui::PopStyleColor();
    }
    ImGui::TextWrapped("%s: %zu groups for %d triangles (%d split for fold-over)",
                       explicit_groups ? "stored groups" : "automatic", geo.groups.size(),
                       num_triangles, geo.folds_split);

    // Automatic grouping parameters: re-group when a slider is released.
    if (!ImGui::IsAnyItemActive()) {
      angle_ = static_cast<float>(state.project.grouping.angle_deg);
      texel_ = static_cast<float>(state.project.pipeline.texel_size_m);
    }
    ImGui::PushItemWidth(-ImGui::CalcTextSize("texel m (0 = auto)").x -
                         ImGui::GetStyle().ItemInnerSpacing.x);
    ImGui::SliderFloat(FitLabelledItem("angle deg").c_str(), &angle_, 0.0f, 90.0f, "%.1f");
    const bool angle_done = ImGui::IsItemDeactivatedAfterEdit();
    slider_px_ = ImGui::GetItemRectSize().x;
    ImGui::DragFloat(FitLabelledItem("texel m (0 = auto)").c_str(), &texel_, 0.0005f, 0.0f, 1.0f,
                     "%.4f");
    const bool texel_done = ImGui::IsItemDeactivatedAfterEdit();
    ImGui::PopItemWidth();
    if (angle_done || texel_done) {
      state.BeginEdit();
      state.project.grouping.angle_deg = angle_;
      state.project.pipeline.texel_size_m = texel_;
      if (angle_done) {  // back to the automatic grouping with the new angle
        state.project.grouping.groups.clear();
        state.project.grouping.edits.clear();
      }
      ApplyProject(ui);
    }
    if (explicit_groups && ImGui::Button("Back to automatic")) {
      state.BeginEdit();
      state.project.grouping.groups.clear();
      state.project.grouping.edits.clear();
      ApplyProject(ui);
    }
    if (!explicit_groups && ImGui::Button("Store these groups")) {
      state.BeginEdit();
      state.project.grouping.groups = geo.groups;
      state.project.grouping.edits.clear();
    }

    // The groups; click to select (ctrl-click adds).
    // Columns as wide as their headers and values (the table scrolls sideways in a narrow
    // panel or at a large font scale rather than cutting them to a letter), as high as its
    // rows up to twelve (with the header) at any font scale: a few groups leave the buttons
    // below it in sight.
    const size_t rows = 1 + std::min<size_t>(geo.groups.size(), 11);
    const float table_height =
        rows * ImGui::GetTextLineHeightWithSpacing() + ImGui::GetStyle().ScrollbarSize;
    if (ImGui::BeginTable("groups", 4,
                          ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY |
                              ImGuiTableFlags_ScrollX | ImGuiTableFlags_SizingFixedFit |
                              ImGuiTableFlags_BordersInnerV,
                          ImVec2(0, table_height))) {
      if (table_font_px_ != ImGui::GetFontSize()) {  // the font scale changed: fit again
        ImGui::TableSetColumnWidthAutoAll(ImGui::GetCurrentTable());
        table_font_px_ = ImGui::GetFontSize();
      }
      ImGui::TableSetupColumn("group");
      ImGui::TableSetupColumn("triangles");
      ImGui::TableSetupColumn("texels");
      ImGui::TableSetupColumn("texel m");
      ImGui::TableHeadersRow();
      for (size_t g = 0; g < geo.groups.size(); ++g) {
        ImGui::TableNextRow();
        ImGui::TableSetColumnIndex(0);
        const bool selected = state.selected_groups.count(static_cast<int>(g)) > 0;
        // The group's colour in the 3D view's "groups" mode (stable across edits).
        const auto rgb = GroupColour(StableGroupKey(geo.groups[g]));
        ImGui::PushID(static_cast<int>(g));
        ImGui::ColorButton("##colour", ImVec4(rgb[0], rgb[1], rgb[2], 1.0f),
                           ImGuiColorEditFlags_NoTooltip | ImGuiColorEditFlags_NoBorder,
                           ImVec2(ImGui::GetTextLineHeight(), ImGui::GetTextLineHeight()));
        ImGui::PopID();
        ImGui::SameLine();
        if (ImGui::Selectable(std::to_string(g).c_str(), selected,
                              ImGuiSelectableFlags_SpanAllColumns)) {
          if (!ImGui::GetIO().KeyCtrl) state.selected_groups.clear();
          if (selected && ImGui::GetIO().KeyCtrl)
            state.selected_groups.erase(static_cast<int>(g));
          else
            state.selected_groups.insert(static_cast<int>(g));
        }
        ImGui::TableSetColumnIndex(1);
        ImGui::Text("%zu", geo.groups[g].triangles.size());
        ImGui::TableSetColumnIndex(2);
        ImGui::Text("%d", geo.buffer_texels[g]);
        ImGui::TableSetColumnIndex(3);
        const double asked =
            geo.groups[g].texel_size_m > 0 ? geo.groups[g].texel_size_m : geo.texel_size_m;
        const double built =
            g < geo.buffer_texel_size_m.size() ? geo.buffer_texel_size_m[g] : asked;
        if (built > asked * 1.001)  // enlarged to fit the buffer's cap: said in amber
          ImGui::TextColored(ImVec4(1.0f, 0.75f, 0.3f, 1.0f), "%.4f (capped)", built);
        else if (geo.groups[g].texel_size_m > 0)
          ImGui::Text("%.4f", geo.groups[g].texel_size_m);
        else
          ImGui::TextDisabled("default");
      }
      ImGui::EndTable();
    }
    ImGui::Text("selected: %zu groups, %zu triangles (pick in the 3D view)",
                state.selected_groups.size(), state.selected_triangles.size());
    if (ImGui::SmallButton("clear selection")) {
      state.selected_groups.clear();
      state.selected_triangles.clear();
    }

    // Edits on the selection.
    std::vector<GroupSpec> result;
    ImGui::BeginDisabled(state.selected_groups.size() < 2);
    if (ImGui::Button("Merge groups"))
      Commit(ui, MergeGroups(geo.groups, num_triangles, state.selected_groups, &result), result);
    ImGui::EndDisabled();
    SameLineIfFits(ButtonWidth("Split triangles"));
    ImGui::BeginDisabled(state.selected_triangles.empty());
    if (ImGui::Button("Split triangles"))
      Commit(ui, SplitTriangles(geo.groups, num_triangles, state.selected_triangles, &result),
             result);
    ImGui::SetNextItemWidth(ImGui::GetFontSize() * 6);
    ImGui::InputInt("##target", &target_group_);
    SameLineIfFits(ButtonWidth("Move triangles to group"));
    if (ImGui::Button("Move triangles to group"))
      Commit(ui,
             MoveTriangles(geo.groups, num_triangles, state.selected_triangles, target_group_,
                           &result),
             result);
    ImGui::EndDisabled();
    ImGui::BeginDisabled(state.selected_groups.empty());
    ImGui::SetNextItemWidth(ImGui::GetFontSize() * 6);
    ImGui::InputFloat("##texel", &group_texel_, 0, 0, "%.4f");
    SameLineIfFits(ButtonWidth("Set texel size (m)"));
    if (ImGui::Button("Set texel size (m)"))
      Commit(ui,
             SetGroupTexelSize(geo.groups, num_triangles, state.selected_groups, group_texel_,
                               &result),
             result);
    ImGui::EndDisabled();
    ImGui::End();
  }

  std::map<std::string, std::string> Report() const override {
    return {{"colours", colours_},
            {"split", split_message_},
            {"coarser", coarse_message_},
            {"angle slider px", std::to_string(slider_px_)}};
  }

 private:
  static void Commit(UiContext& ui, const Status& status, const std::vector<GroupSpec>& groups) {
    AppState& state = *ui.state;
    if (!status.ok()) {
      state.message = "error: " + status.message();
      return;
    }
    state.BeginEdit();
    state.project.grouping.groups = groups;
    state.project.grouping.edits.clear();
    state.selected_groups.clear();
    state.selected_triangles.clear();
    state.message = "grouping edited: " + std::to_string(groups.size()) + " groups";
    ApplyProject(ui);
  }

  float angle_ = 20, texel_ = 0, group_texel_ = 0.01f;
  float slider_px_ = 0;      // the angle slider's width as last drawn, for Report()
  float table_font_px_ = 0;  // the font size the table's columns were last fitted to
  uint64_t checked_geometry_ = 0;
  std::string split_message_;   // why stored groups were split back apart ("" = they held)
  std::string coarse_message_;  // which groups got coarser texels than asked ("" = none)
  std::string colours_;         // "KEY#rrggbb ..." per group, for Report()
  int target_group_ = 0;
};

}  // namespace

std::unique_ptr<Panel> MakeGroupingPanel() { return std::make_unique<GroupingPanel>(); }

}  // namespace fresco
