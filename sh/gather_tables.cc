#include "sh/gather_tables.h"

namespace daylit::sh {

glm::vec3 GatherTables::ProbePosition(int i, int j, int k) const {
  const glm::ivec3 index(i, j, k);
  glm::vec3 p;
  for (int a = 0; a < 3; ++a) {
    p[a] = resolution[a] <= 1 ? 0.5f * (min[a] + max[a])
                              : min[a] + (max[a] - min[a]) * static_cast<float>(index[a]) / static_cast<float>(resolution[a] - 1);
  }
  return p;
}

}  // namespace daylit::sh
