#include "io/octomap_io.h"

#include <octomap/OcTree.h>

#include <sstream>

#include "core/error.h"
#include "io/file_io.h"

namespace fleetmap::io {

void save_octomap(const mapping::OccupancyGrid& grid, const std::filesystem::path& path) {
  octomap::OcTree tree(grid.resolution());
  const double z = 0.5 * grid.resolution();
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      const mapping::CellState s = grid.state({x, y});
      if (s == mapping::CellState::Unknown) continue;
      const Eigen::Vector2d c = grid.geometry().cell_center({x, y});
      tree.updateNode(octomap::point3d(float(c.x()), float(c.y()), float(z)), s == mapping::CellState::Occupied, true);
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
  io::write_file_atomic(path, out.str());
}

}  // namespace fleetmap::io
