// The files `fresco poses verify` writes: DIR/verify.json (docs/contract.md: frames with name,
// rotation_error_deg, position_error_m, flagged; registered; plus thresholds, alignment and
// COLMAP timings) and DIR/verify.png (both errors along the sequence, thresholds dashed,
// flagged frames marked red, frames COLMAP did not register marked grey). Written atomically.
#pragma once

#include <string>

#include "pipeline/core/status.h"
#include "pipeline/poses/colmap_runner.h"
#include "pipeline/poses/verify.h"

namespace fresco {

std::string VerifyJsonText(const VerifyResult& result, const ColmapRunResult& run);
Status WriteVerifyReport(const VerifyResult& result, const ColmapRunResult& run,
                         const std::string& json_path, const std::string& plot_path);

}  // namespace fresco
