#include "mapping/octomap_io.h"

#include <octomap/OcTree.h>

#include <sstream>

#include "core/error.h"
#include "core/file_io.h"

namespace fleetmap::mapping {

void save_octomap(const OccupancyGrid& grid, const std::filesystem::path& path) {
  octomap::OcTree tree(grid.resolution());
  const double z = 0.5 * grid.resolution();
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      const CellState s = grid.state({x, y});
      if (s == CellState::Unknown) continue;
      const Eigen::Vector2d c = grid.geometry().cell_center({x, y});
      tree.updateNode(octomap::point3d(float(c.x()), float(c.y()), float(z)), s == CellState::Occupied, true);
    }
  }
  tree.updateInnerOccupancy();
  tree.toMaxLikelihood();
  tree.prune();
  // The header of OctoMap's writeBinary, then its node encoding. (Debian's liboctomap is built with
  // debug output, and its writeBinaryData prints " done." to stderr; writeBinaryNode does not.)
  std::ostringstream out;
  out << "# Octomap OcTree binary file\n# (feel free to add / change comments, but leave the first line as it is!)\n#\n"
      << "id " << tree.getTreeType() << "\nsize " << tree.size() << "\nres " << tree.getResolution() << "\ndata\n";
  if (tree.getRoot() != nullptr) tree.writeBinaryNode(out, tree.getRoot());
  if (!out) throw Error(path.string() + ": cannot serialise the OcTree");
  core::write_file_atomic(path, out.str());
}

}  // namespace fleetmap::mapping
