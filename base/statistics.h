// Small robust statistics shared by the bake, the fit and the filters.
#pragma once

#include <algorithm>
#include <vector>

namespace daylit {

// The value at fraction `q` (0..1) of `values` in order (index q·n, the last at most), reordering
// them: q = 0.95 is the 95th percentile. `if_empty` when there are none.
template <typename T>
T PercentileInPlace(std::vector<T>& values, double q, T if_empty) {
  if (values.empty()) return if_empty;
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(std::max(q, 0.0) * static_cast<double>(values.size())));
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(k);
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

// The median of `values` (for an even count, the upper of the two middle values), reordering
// them; `if_empty` when there are none.
template <typename T>
T MedianInPlace(std::vector<T>& values, T if_empty) {
  return PercentileInPlace(values, 0.5, if_empty);
}

}  // namespace daylit
