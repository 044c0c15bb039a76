#include "ui/core/natural_sort.h"

#include <algorithm>
#include <cctype>

namespace fresco {
namespace {

bool IsDigit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

}  // namespace

bool NaturalLess(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (IsDigit(a[i]) && IsDigit(b[j])) {
      const size_t run_a = i, run_b = j;
      while (i < a.size() && IsDigit(a[i])) ++i;
      while (j < b.size() && IsDigit(b[j])) ++j;
      size_t za = run_a, zb = run_b;  // skip leading zeros
      while (za + 1 < i && a[za] == '0') ++za;
      while (zb + 1 < j && b[zb] == '0') ++zb;
      const size_t len_a = i - za, len_b = j - zb;
      if (len_a != len_b) return len_a < len_b;  // more significant digits: larger
      const int cmp = a.compare(za, len_a, b, zb, len_b);
      if (cmp != 0) return cmp < 0;
      if (i - run_a != j - run_b) return i - run_a < j - run_b;
      continue;
    }
    if (a[i] != b[j]) return a[i] < b[j];
    ++i;
    ++j;
  }
  return a.size() - i < b.size() - j;
}

void SortNaturally(std::vector<std::string>* names) {
  std::stable_sort(names->begin(), names->end(), NaturalLess);
}

}  // namespace fresco
