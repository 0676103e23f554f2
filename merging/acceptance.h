#pragma once
// The acceptance index of the wave-algorithm paper (after Birk & Carpin 2006): how much two maps agree when one
// is placed on the other, and the wall-based quality every merge method is judged by.
#include <Eigen/Core>

#include <cstdint>

#include "core/transform2.h"
#include "mapping/occupancy_grid.h"
#include "merging/prepared_grid.h"

namespace fleetmap::merging {

// agr and dis of the wave-algorithm paper, over the cells known in both maps: a cell of b (at its centre, moved by
// b_to_a, rounded to the nearest cell of a) agrees when both have the same state, disagrees when
// one is free and the other occupied. omega = agr / (agr + dis), 0 (not NaN) without common cells.
struct Acceptance {
  std::int64_t agree = 0;
  std::int64_t disagree = 0;
  std::int64_t common() const { return agree + disagree; }
  double omega() const { return common() > 0 ? double(agree) / double(common()) : 0.0; }
};

Acceptance acceptance_index(const mapping::OccupancyGrid& a, const mapping::OccupancyGrid& b,
                            const core::Transform2& b_to_a);

struct QualityOptions {
  double match_distance = 1.5;          // cells: a wall cell matches a wall of the other map this close
  double contradiction_distance = 3.0;  // cells: a wall cell on the other map's free space this far
                                        // from its walls contradicts it
  // score = matched - weight * contradicted: an answer whose walls agree less than
  // weight / (1 + weight) (10: 91%) scores below zero, however large its overlap. Two robots' maps
  // of one building disagree on a few percent of their walls (drift, doors, glass), a right answer
  // of a window of one map on 0-2%; a wrong one that lays a large part of b on similar rooms on
  // 3-10%. With a weight of 3 such a large rough fit outscored a small exact one (on the
  // benchmark of robot-built maps: 741 matched and 73 contradicting against 358 and 0).
  double contradiction_weight = 10.0;
  // cells: a wall cell on the other map's free space at least this far from its walls stands in its
  // open space (AlignmentQuality::open_space_walls). Drift lays walls a cell or three beside the
  // other map's; a wall this far from any of them is a wall where the other map saw a room.
  double open_space_distance = 6.0;
  // metres: a stretch of a common wall's line free in both maps, between matched walls, at least
  // this long is an opening both saw (AlignmentQuality::common_openings): a door is 0.6-1 m.
  double min_opening_m = 0.5;
  // metres: a line of the common walls (the shape below) holds the matched walls within 2 cells of
  // it, and when it is one face of a wall, those seen from the same side within this distance: a
  // face spreads across its line by the laser's noise and the wall's roughness, which are metres,
  // not cells (seen on the benchmark of robot-built maps: at 2.5 cm a noisy wall's face spread over
  // five cells, and its edges counted as seven blocks beyond one corner of a bare hall, merged
  // with another corner of it). The wall's other face, seen from the other side, stays a detail.
  double face_band_m = 0.1;
  // Count the shape of the common walls too (beyond_corner, wall_ends, junction_arms, beyond_room,
  // parallel_lines, off_room_sides, common_openings).
  // Off, they stay 0: enough for placements that are only compared by score and evidence (the
  // rivals of an answer), and a third of the time of a full evaluation.
  bool shape = true;
};

// How well the walls of two maps fit under a transform, counted both ways (b's walls in a, and
// a's walls in b) over the cells that land on known cells of the other map.
struct AlignmentQuality {
  int tested = 0;        // wall cells (not clutter) that land on known cells of the other map
  int matched = 0;       // wall cells near a wall of the other map, seen from the same side
  int contradicted = 0;  // wall cells, and interior cells of filled obstacles (every second row and
                         // column), on the other map's free space far from its walls
  double score = 0.0;      // matched - contradiction_weight * contradicted
  double agreement = 0.0;  // matched / (matched + contradicted); 0 without either
  // The largest group of wall cells of either map that stand in the other's open space (on its
  // free cells, at least open_space_distance cells from its walls), 8-connected in a's cells, not
  // counting obstacles standing alone (clutter, furniture: PrepareOptions::furniture_size_m): a
  // stretch of the building's walls laid across a room or corridor the other map saw free. A
  // closed door (free in the other map, between jambs both maps see) stands only its middle that
  // far from the jambs; two copies of a repeated place laid on each other can put one map's end
  // wall across the other's corridor.
  int open_space_walls = 0;
  Eigen::Vector2d open_space_at = Eigen::Vector2d::Zero();  // the mean of that group, in a's cells
  // Smallest eigenvalue of the information the matched walls give about (tx, ty, theta * radius):
  // how many wall cells' worth pin the weakest direction down. A straight wall alone, or one
  // round obstacle, leaves a direction free and gives ~0.
  double constraint = 0.0;
  // RMS distance to the other map's walls of the walls that land within contradiction_distance of
  // them (matched, or near: a cell or two off), in cells.
  double residual_rms = 0.0;
  // Matched walls (4 x 4 blocks of either map, clutter left out) farther than 2 cells from the two
  // straight lines that hold the most of them: 0 when all the common walls are one corner (two
  // walls), which fits any other corner of a bare room as well.
  int beyond_corner = 0;
  // Matched wall ends (4 x 4 blocks of either map, one for a block any of whose matched cells ends
  // a wall): a straight wall that stops with free space
  // beyond it on its line and on both sides of the line (an opening one sees through: a door jamb,
  // the end of a free-standing wall; not where the view ends), in both maps at the same place. On
  // the lines, but it fixes where along them the maps meet.
  int wall_ends = 0;
  // Of the four half-lines from where those two lines meet, how many carry matched walls (3 blocks
  // or more, beyond 4 cells from the meeting point): 2 for an L (a room's corner, which fits any
  // other corner), 3 for a T (one wall meeting another that goes on past it), 4 for a cross; 0
  // when the two lines are within 30 degrees of parallel. A bare room has no T.
  int junction_arms = 0;
  // The same for the four lines that hold the most: 0 when the common walls are the sides of one
  // rectangular room (or fewer lines), which fits itself turned a half turn.
  int beyond_room = 0;
  // Of those four lines, the ones that hold 8 blocks or more (a wall 16 cells long seen by both
  // maps), run along or square to the strongest (within 10 degrees) and lie a metre or more from a
  // stronger parallel one are sides of a room; the rest (jogs, niches, a door's reveal, slanted
  // walls) are details on its walls. The most sides that run parallel (within 10
  // degrees): at most 2 when the common walls are sides of one rectangular room; 3 or more when a
  // wall runs beside a side (a step in the outline, a partition, the next room's wall).
  int parallel_lines = 0;
  // The blocks on none of those sides: details on the walls, walls beyond the room.
  int off_room_sides = 0;
  // When there are 3 sides or more, at most 2 of them parallel: the least share of either map's
  // free cells more than 4 cells beyond one of the sides, away from the room (1 otherwise). At
  // most 2% when one map saw that room and nothing else, so that its walls tell only the room's size.
  double outside_room = 1.0;
  // And the matched walls half a metre or more inside the outline of all of them (a partition's
  // end, a pillar, furniture): details that pin where in the room the other map lies.
  int room_details = 0;
  // Openings in those lines that both maps saw: stretches of a line at least min_opening_m long
  // between matched walls on it, free in both maps (a door both looked through, where one wall ends
  // and the next begins). Where along its walls a room is, which its size alone does not say.
  int common_openings = 0;
  // When the three lines that hold the most matched walls are one end of a hall (two parallel walls
  // and one across them, the parallel walls' blocks on one side of it) and neither map saw past the
  // two parallel walls (at most 2% of its free cells more than 4 cells outside them): the blocks
  // off those three lines. 0 when the common walls are the closed end of a bare hall or corridor
  // and nothing else, which the other end of a longer hall fits as well: each map may have seen a
  // different end. -1 when the three lines are not such an end, or a map saw rooms beside it, whose
  // place along it tells where the end is (or shape is off).
  int beyond_end = -1;
  double overlap_radius = 0.0;  // RMS distance of the matched walls from their centroid, in cells
  Eigen::Vector2d overlap_centre = Eigen::Vector2d::Zero();  // that centroid, in a's cells
};

AlignmentQuality evaluate_alignment(const PreparedGrid& a, const PreparedGrid& b, const core::Transform2& b_to_a,
                                    const QualityOptions& options = {});

}  // namespace fleetmap::merging
