#pragma once
// Relative transforms from a rendezvous: two robots see each other and exchange their poses.
// All poses and transforms here are in metres and radians in the robots' own map frames.
#include "core/grid_geometry.h"
#include "core/transform2.h"

namespace fleetmap::merging {

// What the two robots measured of each other when they met.
struct MutualObservation {
  double range_self_to_other = 0.0;    // m, the other robot as seen by this one
  double bearing_self_to_other = 0.0;  // rad, in this robot's frame
  double range_other_to_self = 0.0;    // m, this robot as seen by the other
  double bearing_other_to_self = 0.0;  // rad, in the other robot's frame
};

// The map-alignment paper, eq. (7)-(9): the transform of the other robot's map frame into this robot's, from
// both robots' pose estimates in their own maps and the mutual observation:
//   rho = (rho_self,other + rho_other,self) / 2, theta = pi + phi_self,other - phi_other,self,
//   Theta = phi_1 + theta - phi_2,
//   d_x = x_1 + rho cos(phi_1 + phi_self,other) - (x_2 cos Theta - y_2 sin Theta),
//   d_y = y_1 + rho sin(phi_1 + phi_self,other) - (x_2 sin Theta + y_2 cos Theta).
core::Transform2 rendezvous_transform(const core::Pose2& self_pose, const core::Pose2& other_pose,
                                      const MutualObservation& observation);

// D'Alfonso et al., §3.2: T_l0,j0 = T_j,j0 T_l,j T_l,l0^-1 (3x3 homogeneous matrices), the transform from
// the sender r_l's map frame R_l,0 into the receiver r_j's R_j,0. T_j,j0 and T_l,l0 are the robots'
// poses in their maps; T_l,j places r_l in r_j's frame: rotation vartheta = pi + alpha_j,l - alpha_l,j
// and translation d (cos alpha_j,l, sin alpha_j,l), with d their distance, alpha_j,l the bearing at
// which r_j sees r_l and alpha_l,j the bearing at which r_l sees r_j. (The seed prints the
// translation as d (cos vartheta, sin vartheta); r_l lies along the bearing r_j measured, which is
// what is used here; the two agree only when vartheta = alpha_j,l.)
core::Transform2 rendezvous_transform_matrices(const core::Pose2& receiver_pose, const core::Pose2& sender_pose,
                                               double distance, double bearing_receiver_to_sender,
                                               double bearing_sender_to_receiver);

// A transform between two maps' world frames (metres) as a transform between their cells (cell
// centres at integers, as merge.h), and back. Throws fleetmap::Error unless both grids have the
// same resolution (a rigid transform cannot rescale).
core::Transform2 cells_from_world(const core::GridGeometry& a, const core::GridGeometry& b,
                                  const core::Transform2& b_world_to_a_world);
core::Transform2 world_from_cells(const core::GridGeometry& a, const core::GridGeometry& b,
                                  const core::Transform2& b_cells_to_a_cells);

// The image convention of `fleetmap merge`: pixel (u, v) (u = column, v = row from the top) of
// input b lies at R(theta) (u, v) + (tx, ty) in input a's pixel grid. Cells count rows from the
// bottom, so the conversion flips rows: theta changes sign. It is its own inverse (cells <-> pixels).
core::Transform2 flip_rows(const core::Transform2& b_to_a, int height_a, int height_b);

}  // namespace fleetmap::merging
