// Names ordered as people read them: runs of digits compare by their value, so "warped_b2"
// comes before "warped_b19" (plain text order puts b19 first). Pure logic, no ImGui.
#pragma once

#include <string>
#include <vector>

namespace fresco {

// True when `a` sorts before `b`: text compared character by character, except that runs
// of decimal digits compare as numbers (leading zeros ignored; on a tie the shorter run
// first, so "b2" < "b02").
bool NaturalLess(const std::string& a, const std::string& b);

// Sorts `names` with NaturalLess (stable).
void SortNaturally(std::vector<std::string>* names);

}  // namespace fresco
