#include "ui/panels/live_status_section.h"  // imgui.h first: imgui_stdlib.h needs it

#include <imgui_stdlib.h>

#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>

#include "ui/panels/panels.h"

namespace fresco {
namespace {

const ImVec4 kGood(0.45f, 0.85f, 0.45f, 1.0f);
const ImVec4 kWarn(1.0f, 0.75f, 0.3f, 1.0f);
const ImVec4 kBad(1.0f, 0.4f, 0.4f, 1.0f);

ImVec4 StateColour(const std::string& state) {
  if (state == "receiving") return kGood;
  if (state == "error" || state == "ended") return kBad;
  return kWarn;  // connecting, waiting for frames, stalled
}

// <project folder>/recordings/YYYYMMDD-HHMMSS.
std::string DefaultRecordDir(const Project& project) {
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &local);
  const std::filesystem::path folder = std::filesystem::path(project.file_path).parent_path();
  return (folder / "recordings" / stamp).string();
}

void WrappedColored(const ImVec4& colour, const std::string& text) {
  ImGui::PushStyleColor(ImGuiCol_Text, colour);
  ImGui::TextWrapped("%s", text.c_str());
  ImGui::PopStyleColor();
}

std::string Format(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

}  // namespace

void LiveStatusSection::Draw(UiContext& ui, const LiveStatus& live) {
  report_.clear();
  if (!live.active) return;
  ImGui::Separator();
  ImGui::TextDisabled("Live sources");
  ImGui::Text("video");
  ImGui::SameLine(60);
  ImGui::TextColored(StateColour(live.state), "%s", live.state.c_str());
  ImGui::SameLine();
  ImGui::TextWrapped("%s", live.video.c_str());
  ImGui::Text("poses");
  ImGui::SameLine(60);
  std::string pose_state = "file";
  if (live.pose_feed) {
    pose_state = live.feed.connected ? "connected" : "disconnected";
    ImGui::TextColored(live.feed.connected ? kGood : kWarn, "%s", pose_state.c_str());
  } else {
    ImGui::TextDisabled("file");
  }
  ImGui::SameLine();
  ImGui::TextWrapped("%s", live.poses.c_str());
  const LiveFramesStats& f = live.frames;
  ImGui::Text("frames: %lld received, %lld painted", f.frames_received, live.frames_painted);
  ImGui::Text("        %lld dropped, %lld without pose", f.frames_dropped + f.frames_held_dropped,
              f.frames_without_pose);
  ImGui::Text("queue: high water %d of %d; clock %s", f.queue_high_water, f.queue_capacity,
              f.video_clock.c_str());
  if (live.pose_feed)
    ImGui::Text("tracker: %lld poses, %lld reconnects", live.feed.poses, live.feed.reconnects);
  if (const PoseFeedGap* gap = live.last_gap(); live.pose_feed && gap) {
    const double tracker_s = gap->tracker_gap_s();
    const std::string span = std::isfinite(tracker_s)
                                 ? Format("%.3f s of tracker time", tracker_s)
                                 : std::string("tracker time not known yet");
    ImGui::Text("last gap: %.2f s disconnected, %s", gap->disconnected_s, span.c_str());
  }
  const std::string lag = live.pose_lag_known ? Format("%+.3f s", live.pose_lag_s) : "-";
  ImGui::Text("pose-match lag: %s", lag.c_str());
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "the tracker's newest pose time minus the last frame's pose time\n"
        "(> 0: the tracker is ahead of the video)");
  std::string offset = Format("%.4f s", f.time_offset_s);
  if (live.offset_estimating)
    offset += " (estimating...)";
  else if (f.offset_estimated)
    offset += Format(" (estimated, score %.2f)", f.estimate.score);
  else if (!f.estimate.note.empty())
    offset += " (not estimated: " + f.estimate.note + ")";
  else
    offset += " (as set)";
  ImGui::TextWrapped("time offset: %s", offset.c_str());
  if (!f.offset_track.empty())
    ImGui::Text("tracked: %zu re-estimates, last %.4f s (%s)", f.offset_track.size(),
                f.offset_track.back().offset_s, f.offset_track.back().applied ? "applied" : "kept");
  if (!live.problem.empty()) WrappedColored(kBad, live.problem);

  if (live.streams > 1) {
    ImGui::TextWrapped("%d streams painting: the figures above are the first live stream's "
                       "(each stream's are in fresco run's metrics.json); recording needs a "
                       "project with one stream.",
                       live.streams);
  } else {
    DrawRecording(ui, live);
  }

  report_["live.state"] = live.state;
  report_["live.poses_state"] = pose_state;
  report_["live.frames_received"] = std::to_string(f.frames_received);
  report_["live.frames_dropped"] = std::to_string(f.frames_dropped + f.frames_held_dropped);
  report_["live.frames_painted"] = std::to_string(live.frames_painted);
  report_["live.pose_lag"] = lag;
  report_["live.time_offset"] = offset;
  report_["live.problem"] = live.problem;
  report_["live.recording"] = live.recording ? live.record_dir : "";
}

void LiveStatusSection::DrawRecording(UiContext& ui, const LiveStatus& live) {
  // Record toggle: the worker's state is the truth; a click asks it to change.
  bool recording = live.recording;
  if (ImGui::Checkbox("Record", &recording)) {
    if (recording && record_dir_.empty()) record_dir_ = DefaultRecordDir(ui.state->project);
    ui.runner->Record(recording ? record_dir_ : "");
    if (recording) record_dir_.clear();  // the next recording gets a fresh default
  }
  ImGui::SameLine();
  ImGui::SetNextItemWidth(-1);
  ImGui::BeginDisabled(live.recording);
  ImGui::InputTextWithHint("##record", "folder (default: recordings/<time>)", &record_dir_);
  ImGui::EndDisabled();
  if (live.recording) {
    WrappedColored(kBad, "recording: " + std::to_string(live.recorded_frames) + " frames to " +
                             live.record_dir);
  } else if (!live.recorded_project.empty()) {
    ImGui::TextWrapped("recorded %d frames: %s", live.recorded_frames,
                       live.recorded_project.c_str());
    if (ImGui::Button("Open the recording")) RequestOpen(ui, live.recorded_project);
  }
  if (!live.record_error.empty()) WrappedColored(kBad, "recording failed: " + live.record_error);
}

}  // namespace fresco
