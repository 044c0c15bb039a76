#include "pipeline/eval/eval_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include <nlohmann/json.hpp>

#include "pipeline/paint/auto_modes.h"

namespace fresco {
namespace {

using json = nlohmann::json;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// `higher_is_worse`: the worst is the largest value.
// Over the captures where the figure is a number (NaN: not measured there).
FigureSpread Spread(const std::vector<const CaptureEval*>& group,
                    const std::function<double(const CaptureEval&)>& figure, bool higher_is_worse,
                    bool movers_only = false) {
  std::vector<double> values;
  for (const CaptureEval* c : group)
    if ((!movers_only || c->has_movers) && std::isfinite(figure(*c))) values.push_back(figure(*c));
  FigureSpread s;
  s.count = static_cast<int>(values.size());
  if (values.empty()) return s;
  s.median = Median(values);
  s.worst = higher_is_worse ? *std::max_element(values.begin(), values.end())
                            : *std::min_element(values.begin(), values.end());
  return s;
}

FamilySummary Summarize(const std::string& family, const std::vector<const CaptureEval*>& group) {
  FamilySummary f;
  f.family = family;
  f.captures = static_cast<int>(group.size());
  f.truth_psnr_db = Spread(
      group, [](const CaptureEval& c) { return c.truth_psnr_db; }, false);
  f.truth_one_minus_ncc = Spread(
      group, [](const CaptureEval& c) { return c.truth_one_minus_ncc; }, true);
  f.psnr_db = Spread(
      group, [](const CaptureEval& c) { return c.psnr_db; }, false);
  f.one_minus_ncc = Spread(
      group, [](const CaptureEval& c) { return c.one_minus_ncc; }, true);
  f.mover_leak = Spread(
      group, [](const CaptureEval& c) { return c.mover_leak; }, true, true);
  f.static_texels_painted = Spread(
      group, [](const CaptureEval& c) { return c.open_coverage; }, false, true);
  f.paint_fps = Spread(
      group, [](const CaptureEval& c) { return c.paint_fps; }, false);
  f.coverage = Spread(
      group, [](const CaptureEval& c) { return c.coverage; }, false);
  f.recovered = Spread(
      group, [](const CaptureEval& c) { return c.recovered; }, false);
  f.exact_poses_gain_db = Spread(
      group,
      [](const CaptureEval& c) {
        return c.noisy_poses ? kNoFigure : c.truth_psnr_db - c.unrefined_truth_psnr_db;
      },
      false);
  return f;
}

json SpreadJson(const FigureSpread& s) {
  if (s.count == 0) return nullptr;
  return {{"median", s.median}, {"worst", s.worst}, {"captures", s.count}};
}

}  // namespace

std::vector<FamilySummary> SummarizeByFamily(const std::vector<CaptureEval>& results) {
  std::vector<std::string> order;
  for (const CaptureEval& c : results)
    if (std::find(order.begin(), order.end(), c.family) == order.end()) order.push_back(c.family);
  std::vector<FamilySummary> out;
  std::vector<const CaptureEval*> all;
  for (const CaptureEval& c : results) all.push_back(&c);
  for (const std::string& family : order) {
    std::vector<const CaptureEval*> group;
    for (const CaptureEval& c : results)
      if (c.family == family) group.push_back(&c);
    out.push_back(Summarize(family, group));
  }
  out.push_back(Summarize("all", all));
  return out;
}

// "on 1.84" for the text table; "-" when not auto.
std::string DecisionCell(const AutoDecision& d) {
  if (!d.is_auto()) return "-";
  char cell[48];
  std::snprintf(cell, sizeof cell, "%s %.3g", d.StateName(), d.evidence);
  return cell;
}

std::string EvalToJson(const std::vector<std::string>& settings,
                       const std::vector<CaptureEval>& results,
                       const std::vector<FamilySummary>& families) {
  json root;
  root["settings"] = settings;
  root["captures"] = json::array();
  for (const CaptureEval& c : results) {
    json row = {
        {"name", c.name},
        {"family", c.family},
        {"frames", c.frames},
        {"painted_frames", c.painted_frames},
        {"holdout_frames", c.holdout_frames},
        {"generated", c.generated},
        {"generate_seconds", c.generate_seconds},
        {"paint_fps", c.paint_fps},
        {"psnr_db", c.psnr_db},
        {"one_minus_ncc", c.one_minus_ncc},
        {"completeness", c.completeness},
        {"coverage", c.coverage},
        {"truth", {{"psnr_db", c.truth_psnr_db}, {"one_minus_ncc", c.truth_one_minus_ncc}}}};
    row["mover_leak"] = c.has_movers ? json(c.mover_leak) : json(nullptr);
    if (c.has_movers)
      row["movers"] = {{"region_error", c.mover_region_error},
                       {"texels", c.mover_texels},
                       {"dominated_texels", c.mover_dominated_texels},
                       {"open_coverage", c.open_coverage},
                       {"texels_by_why",
                        {{"never_seen_without", c.mover_never_open},
                         {"without_kept_out", c.mover_open_masked},
                         {"without_not_taken", c.mover_open_passed},
                         {"without_replaced", c.mover_open_replaced}}}};
    row["auto"] = json::parse(AutoDecisionsJson(c.decisions));
    if (std::isfinite(c.movers_across_views)) row["movers_across_views"] = c.movers_across_views;
    row["noisy_poses"] = c.noisy_poses;
    if (c.joint_ran)
      row["joint_poses"] = {{"applied", c.joint_applied},
                            {"decided_on_frames", c.joint_decided_on_frames},
                            {"check_ratio", c.joint_check_ratio},
                            {"one_end_ratio", c.joint_one_end_ratio},
                            {"tracks_ratio", c.joint_tracks_ratio}};
    if (std::isfinite(c.unrefined_truth_psnr_db)) {
      const auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
      row["refinement"] = {{"unrefined_truth_psnr_db", number(c.unrefined_truth_psnr_db)},
                           {"true_poses_truth_psnr_db", number(c.true_pose_truth_psnr_db)},
                           {"recovered", number(c.recovered)}};
    }
    root["captures"].push_back(row);
  }
  root["families"] = json::array();
  for (const FamilySummary& f : families) {
    root["families"].push_back({{"family", f.family},
                                {"captures", f.captures},
                                {"truth_psnr_db", SpreadJson(f.truth_psnr_db)},
                                {"truth_one_minus_ncc", SpreadJson(f.truth_one_minus_ncc)},
                                {"psnr_db", SpreadJson(f.psnr_db)},
                                {"one_minus_ncc", SpreadJson(f.one_minus_ncc)},
                                {"mover_leak", SpreadJson(f.mover_leak)},
                                {"static_texels_painted", SpreadJson(f.static_texels_painted)},
                                {"paint_fps", SpreadJson(f.paint_fps)},
                                {"coverage", SpreadJson(f.coverage)},
                                {"recovered", SpreadJson(f.recovered)},
                                {"exact_poses_gain_db", SpreadJson(f.exact_poses_gain_db)}});
  }
  return root.dump(2) + "\n";
}

std::string EvalToText(const std::vector<CaptureEval>& results,
                       const std::vector<FamilySummary>& families) {
  std::string out =
      "| capture | family | truth PSNR dB | truth 1-NCC | rephoto PSNR dB | rephoto 1-NCC | "
      "mover leak % | coverage % | paint fps | auto refine (misalignment, texels) | auto "
      "background (foreground fraction) |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  char line[400];
  for (const CaptureEval& c : results) {
    char leak[32] = "-";
    if (c.has_movers) std::snprintf(leak, sizeof leak, "%.3f", 100 * c.mover_leak);
    std::snprintf(
        line, sizeof line, "| %s | %s | %.2f | %.4f | %.2f | %.4f | %s | %.1f | %.0f | %s | %s |\n",
        c.name.c_str(), c.family.c_str(), c.truth_psnr_db, c.truth_one_minus_ncc, c.psnr_db,
        c.one_minus_ncc, leak, 100 * c.coverage, c.paint_fps,
        DecisionCell(c.decisions.refine).c_str(), DecisionCell(c.decisions.background).c_str());
    out += line;
  }
  out +=
      "\n| family | captures | truth PSNR dB median / worst | rephoto PSNR dB median / worst | "
      "mover leak % median / worst | static texels painted % median / worst (with movers) | "
      "paint fps median / worst |\n|---|---|---|---|---|---|---|\n";
  for (const FamilySummary& f : families) {
    char leak[48] = "-", painted[48] = "-";
    if (f.mover_leak.count > 0)
      std::snprintf(leak, sizeof leak, "%.3f / %.3f", 100 * f.mover_leak.median,
                    100 * f.mover_leak.worst);
    if (f.static_texels_painted.count > 0)
      std::snprintf(painted, sizeof painted, "%.1f / %.1f", 100 * f.static_texels_painted.median,
                    100 * f.static_texels_painted.worst);
    std::snprintf(
        line, sizeof line, "| %s | %d | %.2f / %.2f | %.2f / %.2f | %s | %s | %.0f / %.0f |\n",
        f.family.c_str(), f.captures, f.truth_psnr_db.median, f.truth_psnr_db.worst,
        f.psnr_db.median, f.psnr_db.worst, leak, painted, f.paint_fps.median, f.paint_fps.worst);
    out += line;
  }
  bool movers = false;
  for (const CaptureEval& c : results) movers |= c.has_movers;
  if (movers) {
    // Where the movers are, how much of the static scene is painted and why the movers that
    // are painted were (MoverProvenance::Figures, % of the painted texels).
    out +=
        "\n| capture with movers | mover leak % | static texels painted % | mover texels % | "
        "never seen without | every view without kept out | one not taken | one replaced "
        "|\n|---|---|---|---|---|---|---|---|\n";
    for (const CaptureEval& c : results) {
      if (!c.has_movers) continue;
      std::snprintf(line, sizeof line, "| %s | %.3f | %.1f | %.2f | %.2f | %.2f | %.2f | %.2f |\n",
                    c.name.c_str(), 100 * c.mover_leak, 100 * c.open_coverage, 100 * c.mover_texels,
                    100 * c.mover_never_open, 100 * c.mover_open_masked, 100 * c.mover_open_passed,
                    100 * c.mover_open_replaced);
      out += line;
    }
  }
  bool references = false;
  for (const CaptureEval& c : results) references |= std::isfinite(c.unrefined_truth_psnr_db);
  if (!references) return out;
  out +=
      "\n| capture | truth PSNR dB | refinement off | true poses | recovered % |\n"
      "|---|---|---|---|---|\n";
  for (const CaptureEval& c : results) {
    char perfect[32] = "-", recovered[32] = "-";
    if (std::isfinite(c.true_pose_truth_psnr_db))
      std::snprintf(perfect, sizeof perfect, "%.2f", c.true_pose_truth_psnr_db);
    if (std::isfinite(c.recovered))
      std::snprintf(recovered, sizeof recovered, "%.0f", 100 * c.recovered);
    std::snprintf(line, sizeof line, "| %s | %.2f | %.2f | %s | %s |\n", c.name.c_str(),
                  c.truth_psnr_db, c.unrefined_truth_psnr_db, perfect, recovered);
    out += line;
  }
  out +=
      "\n| family | recovered % median / worst (noisy poses) | dB against refinement off "
      "median / worst (exact poses) |\n|---|---|---|\n";
  for (const FamilySummary& f : families) {
    char recovered[48] = "-", gain[48] = "-";
    if (f.recovered.count > 0)
      std::snprintf(recovered, sizeof recovered, "%.0f / %.0f (%d)", 100 * f.recovered.median,
                    100 * f.recovered.worst, f.recovered.count);
    if (f.exact_poses_gain_db.count > 0)
      std::snprintf(gain, sizeof gain, "%+.2f / %+.2f (%d)", f.exact_poses_gain_db.median,
                    f.exact_poses_gain_db.worst, f.exact_poses_gain_db.count);
    std::snprintf(line, sizeof line, "| %s | %s | %s |\n", f.family.c_str(), recovered, gain);
    out += line;
  }
  return out;
}

}  // namespace fresco
