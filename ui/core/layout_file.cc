#include "ui/core/layout_file.h"

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "pipeline/core/atomic_file.h"

namespace fresco {

Status SaveLayoutFile(const std::string& path, const SavedLayout& saved) {
  const nlohmann::json j = {{"fractions", saved.layout.Fractions()},
                            {"panels", saved.layout.Panels()},
                            {"font_scale", saved.font_scale}};
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
  return WriteFileAtomic(path, j.dump(2) + "\n");
}

Status LoadLayoutFile(const std::string& path, SavedLayout* saved) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return Status::Ok();
  std::string text;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &text));
  std::vector<float> fractions;
  std::vector<std::string> panels;
  float font_scale = 1;
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    fractions = j.at("fractions").get<std::vector<float>>();
    font_scale = j.at("font_scale").get<float>();
    if (j.contains("panels")) panels = j.at("panels").get<std::vector<std::string>>();
  } catch (const std::exception& e) {
    return Status::Error(path + ": not a layout file (" + e.what() + ")");
  }
  if (!(font_scale >= 0.5f && font_scale <= 4.0f))
    return Status::Error(path + ": font_scale " + std::to_string(font_scale) +
                         " is outside 0.5..4");
  for (float f : fractions)
    if (!(f > 0 && f < 1)) return Status::Error(path + ": fractions must lie in (0, 1)");
  saved->font_scale = font_scale;
  if (fractions.size() == saved->layout.Fractions().size()) saved->layout.SetFractions(fractions);
  if (!panels.empty()) saved->layout.SetPanels(panels);
  return Status::Ok();
}

}  // namespace fresco
