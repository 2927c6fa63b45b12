#ifndef HPOSE_CORE_SEARCH_FREE_SPACE_GROW_H_
#define HPOSE_CORE_SEARCH_FREE_SPACE_GROW_H_

#include <vector>

#include "core/templates/voxel_template.h"

namespace hpose {

// How many cells beyond the box of a cluster's cells a search of `tpl` may read free space, at
// each height (z cell 0 .. the template's highest): the search's origin margin (how far beyond
// the box it places the template's origin) plus how far the template reaches from its origin at
// that height, plus a voxel's diagonal and the rounding of rotated voxels to the lattice. -1
// where the template has no voxel (nothing is read there). Cells below the floor (z < 0) are
// never free space and are left out.
std::vector<int> FreeSpaceGrow(const VoxelTemplate& tpl, double origin_margin_m,
                               double resolution_m);

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_FREE_SPACE_GROW_H_
