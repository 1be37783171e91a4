// Small robust statistics shared by the bake, the fit and the filters.
#pragma once

#include <algorithm>
#include <vector>

namespace daylit {

// The median of `values` (for an even count, the upper of the two middle values), reordering
// them; `if_empty` when there are none.
template <typename T>
T MedianInPlace(std::vector<T>& values, T if_empty) {
  if (values.empty()) return if_empty;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace daylit
