#include "geods/texture/neighborhood.hpp"

#include <string>

#include "geods/core/error.hpp"

namespace geods::texture {

NeighborhoodShape NeighborhoodShape::make(std::size_t size, std::size_t parent_size, bool causal) {
  if (size < 3 || size % 2 == 0 || size > 63)
    throw Error("texture: the neighborhood must be an odd size from 3 to 63, got " + std::to_string(size));
  if (parent_size != 0 && (parent_size % 2 == 0 || parent_size > 63))
    throw Error("texture: the parent neighborhood must be an odd size up to 63, got " + std::to_string(parent_size));
  NeighborhoodShape shape;
  shape.fine_half = int(size / 2);
  shape.parent_half = parent_size ? int(parent_size / 2) : 0;
  const int h = shape.fine_half;
  for (int dy = -h; dy <= (causal ? 0 : h); ++dy)
    for (int dx = -h; dx <= h; ++dx) {
      if (dy == 0 && dx == 0) {
        if (causal) break;  // the causal window ends just before p
        continue;
      }
      shape.fine.push_back({dx, dy});
    }
  const int m = shape.parent_half;
  if (parent_size)
    for (int dy = -m; dy <= m; ++dy)
      for (int dx = -m; dx <= m; ++dx) shape.parent.push_back({dx, dy});
  return shape;
}

}  // namespace geods::texture
