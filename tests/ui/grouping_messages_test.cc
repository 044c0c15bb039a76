// The Grouping panel's messages after a merge, the app driven headless: a merge split back
// apart for fold-over names the numbers its parts have now (as the panel lists them), and a
// merge whose buffer exceeds max_buffer_texels says that its texels were made coarser.
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_internal.h>

#include "tests/test_support.h"
#include "tests/ui/headless_ui.h"

namespace fresco {
namespace {

using testing::HeadlessApp;

// The numbers (in the painting) of the groups holding stored group `stored`'s triangles.
std::set<int> PartsOf(HeadlessApp& app, int stored) {
  const SessionGeometry& geo = *app.runner.Snapshot()->geometry;
  std::set<int> parts;
  for (int t : app.state.project.grouping.groups[stored].triangles)
    parts.insert(geo.buffer_of_triangle[t]);
  return parts;
}

TEST(GroupingMessages, ASplitBackNamesTheNumbersItsPartsHaveNow) {
  HeadlessApp app(testing::Capture() + "/project.json", 2);
  bool split = false;
  for (int other = 1; other < 6 && !split; ++other) {
    app.state.project.grouping.groups.clear();
    ApplyProject(app.ui);
    app.runner.WaitIdle();
    app.Frames(2);
    testing::MergeAndApply(app, 0, other);
    const std::string message = app.ReportOf("Grouping", "split");
    if (message.empty()) continue;
    split = true;
    for (size_t g = 0; g < app.state.project.grouping.groups.size(); ++g) {
      const std::set<int> parts = PartsOf(app, static_cast<int>(g));
      if (parts.size() < 2) continue;
      ASSERT_EQ(parts.size(), 2u);
      const std::string named = "now groups " + std::to_string(*parts.begin()) + " and " +
                                std::to_string(*parts.rbegin());
      EXPECT_NE(message.find(named), std::string::npos) << message;
      EXPECT_NE(app.state.message.find(named), std::string::npos) << app.state.message;
    }
  }
  EXPECT_TRUE(split) << "opposite walls fold over";
}

TEST(GroupingMessages, AMergeWhoseTexelsWereCappedSaysSo) {
  HeadlessApp app(testing::Capture() + "/project.json", 2);
  // A texel size of its own and a cap just above the largest wall's buffer: every wall alone
  // keeps its texels.
  app.state.project.pipeline.texel_size_m = 0.02;
  ApplyProject(app.ui);
  app.runner.WaitIdle();
  app.Frames(2);
  int64_t largest = 0;
  for (int64_t n : app.runner.Snapshot()->geometry->buffer_size_texels)
    largest = std::max(largest, n);
  ASSERT_GT(largest, 0);
  app.state.project.pipeline.max_buffer_texels = static_cast<int>(largest * 1.1);
  ApplyProject(app.ui);
  app.runner.WaitIdle();
  app.Frames(2);
  EXPECT_EQ(app.ReportOf("Grouping", "coarser"), "");
  // Two walls at a right angle merged: one buffer larger than the cap, its texels coarser.
  bool capped = false;
  for (int other = 1; other < 6 && !capped; ++other) {
    app.state.project.grouping.groups.clear();
    ApplyProject(app.ui);
    app.runner.WaitIdle();
    app.Frames(2);
    testing::MergeAndApply(app, 0, other);
    if (!app.ReportOf("Grouping", "split").empty()) continue;  // folded over instead
    const std::string message = app.ReportOf("Grouping", "coarser");
    ASSERT_NE(message, "") << "a merge whose buffer exceeds the cap, not said";
    capped = true;
    EXPECT_NE(message.find("coarser texels: 1 group"), std::string::npos) << message;
    const std::set<int> merged = PartsOf(app, 0);
    ASSERT_EQ(merged.size(), 1u);
    EXPECT_NE(message.find("group " + std::to_string(*merged.begin()) + ": "), std::string::npos)
        << message;
    EXPECT_NE(app.state.message.find("coarser texels"), std::string::npos) << app.state.message;
  }
  EXPECT_TRUE(capped);
}

// After a merge split back apart (its message above the table), the Grouping panel of the
// 1920 x 1080 window shows its six groups and the buttons below them without scrolling: the
// table is as high as its rows (before: twelve rows high whatever the groups, and the merge
// and split buttons went out of sight below the messages).
TEST(GroupingMessages, AFewGroupsLeaveTheButtonsBelowTheTableInSight) {
  HeadlessApp app(testing::Capture() + "/project.json", 2, ImVec2(1920, 1080));
  for (int other = 1; other < 6 && app.ReportOf("Grouping", "split").empty(); ++other) {
    app.state.project.grouping.groups.clear();
    ApplyProject(app.ui);
    app.runner.WaitIdle();
    app.Frames(2);
    testing::MergeAndApply(app, 0, other);
  }
  ASSERT_NE(app.ReportOf("Grouping", "split"), "") << "opposite walls fold over";
  app.Frames(2);
  ImGuiWindow* grouping = HeadlessApp::Window("Grouping");
  ImGuiTable* table = ImGui::TableFindByID(grouping->GetID("groups"));
  ASSERT_NE(table, nullptr);
  const size_t groups = app.runner.Snapshot()->geometry->groups.size();
  ASSERT_EQ(groups, 6u);
  const float row = ImGui::GetTextLineHeightWithSpacing();
  EXPECT_LE(table->OuterRect.GetHeight(), (groups + 1) * row + ImGui::GetStyle().ScrollbarSize + 1)
      << "the table is higher than its " << groups << " groups";
  EXPECT_EQ(grouping->ScrollMax.y, 0) << "the buttons below the table are out of sight";
}

}  // namespace
}  // namespace fresco
