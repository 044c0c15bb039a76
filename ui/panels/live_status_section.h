// The Pipeline panel's section for live sources (cameras, streams): each source's state (receiving,
// stalled, ended, disconnected), frames received / painted / dropped, the queue, the
// pose-match lag, the time offset (estimated or set), and the Record toggle that records
// the session as a project to replay (opened from here).
#pragma once

#include <map>
#include <string>

#include "ui/core/panel.h"

namespace fresco {

class LiveStatusSection {
 public:
  // Draws the section for `live` (nothing when the project's sources are files).
  void Draw(UiContext& ui, const LiveStatus& live);
  // What it shows, for the panel's Report() (`live.*` keys).
  const std::map<std::string, std::string>& report() const { return report_; }

 private:
  // The Record toggle and the recording's state (a project with one stream).
  void DrawRecording(UiContext& ui, const LiveStatus& live);
  std::string record_dir_;
  std::map<std::string, std::string> report_;
};

}  // namespace fresco
