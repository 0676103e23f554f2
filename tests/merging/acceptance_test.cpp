#include "merging/acceptance.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/random.h"

#include "tests/merging/merging_test_support.h"

namespace fleetmap::merging {
namespace {

using testing::grid_from_text;

TEST(AcceptanceIndex, CountsAgreementAndDisagreementOverCommonCells) {
  const auto a = grid_from_text({"#..", ".#.", "  ."});
  const auto b = grid_from_text({"#.#", "...", "..."});
  // Identity: common cells are those known in both. a (bottom row first): y0 "  .", y1 ".#.", y2 "#..".
  // Agree: (2,0) free-free, (0,1), (2,1), (0,2), (1,2). Disagree: (1,1) occ-free, (2,2) free-occ.
  const Acceptance acc = acceptance_index(a, b, core::Transform2::identity());
  EXPECT_EQ(acc.agree, 5);
  EXPECT_EQ(acc.disagree, 2);
  EXPECT_DOUBLE_EQ(acc.omega(), 5.0 / 7.0);
}

TEST(AcceptanceIndex, IsZeroNotNanWithoutCommonCells) {
  const auto a = grid_from_text({"#.", ".."});
  const auto b = grid_from_text({"..", ".#"});
  const Acceptance far = acceptance_index(a, b, core::Transform2(100.0, 0.0, 0.0));
  EXPECT_EQ(far.common(), 0);
  EXPECT_EQ(far.omega(), 0.0);
  const auto unknown = grid_from_text({"  ", "  "});
  EXPECT_EQ(acceptance_index(a, unknown, core::Transform2::identity()).omega(), 0.0);
}

TEST(AcceptanceIndex, FollowsTheTransform) {
  // b is a shifted one column to the right: a's column x is b's column x + 1.
  const auto a = grid_from_text({"#..#", ".#..", "..#."});
  const auto b = grid_from_text({" #..#", " .#..", " ..#."});
  EXPECT_DOUBLE_EQ(acceptance_index(a, b, core::Transform2(-1.0, 0.0, 0.0)).omega(), 1.0);
  EXPECT_LT(acceptance_index(a, b, core::Transform2::identity()).omega(), 0.7);
}

TEST(AlignmentQuality, RewardsTheRightPlacementOverAShiftedOne) {
  const auto source = testing::source_map("office");
  core::Random random(3);
  CropPairOptions o = testing::half_overlap_crops(source);
  const CropPair pair = make_crop_pair(source, o, random);
  const PreparedGrid a(pair.a), b(pair.b);
  const AlignmentQuality right = evaluate_alignment(a, b, pair.b_to_a);
  const AlignmentQuality shifted = evaluate_alignment(a, b, core::Transform2(7.0, 0.0, 0.0) * pair.b_to_a);
  EXPECT_GT(right.agreement, 0.99);
  EXPECT_GT(right.matched, 300);
  EXPECT_GT(right.score, shifted.score);
  EXPECT_GT(shifted.contradicted, 10 * std::max(1, right.contradicted));
  // A room's worth of walls in every direction.
  EXPECT_GT(right.constraint, 10.0);
}

TEST(AlignmentQuality, AStraightWallLeavesADirectionFree) {
  std::vector<std::string> rows(30, std::string(60, '.'));
  rows[15] = std::string(60, '#');
  const auto g = grid_from_text(rows);
  const PreparedGrid a(g), b(g);
  const AlignmentQuality q = evaluate_alignment(a, b, core::Transform2::identity());
  EXPECT_GT(q.matched, 100);
  EXPECT_NEAR(q.constraint, 0.0, 1.0);
}

// Two rooms on either side of one wall: laid edge to edge along it, each map's wall lies on the
// other's wall, but one robot saw it from the left and the other from the right. That is no match
// (else neighbouring rooms would fit each other as well as the right answer does).
TEST(AlignmentQuality, WallsSeenFromOppositeSidesDoNotMatch) {
  std::vector<std::string> left(30, std::string(30, '?')), right = left;
  for (auto& r : left) r.replace(0, 15, std::string(14, '.') + "#");
  for (auto& r : right) r.replace(14, 16, "#" + std::string(15, '.'));
  const auto left_map = grid_from_text(left), right_map = grid_from_text(right);  // outlive the prepared grids
  const PreparedGrid a(left_map), b(right_map), same(left_map);
  const AlignmentQuality opposite = evaluate_alignment(a, b, core::Transform2::identity());
  const AlignmentQuality seen_alike = evaluate_alignment(a, same, core::Transform2::identity());
  EXPECT_GT(seen_alike.matched, 40);  // the 30-cell wall, from both maps
  EXPECT_EQ(opposite.matched, 0);
}

// A wall with a door opening: at the right placement both maps show the opening's two jambs at the
// same place (wall ends, which tell where along the wall the maps meet); slid along the wall, or
// without an opening, there are none.
TEST(AlignmentQuality, CountsDoorJambsSeenByBothMapsAtOnePlace) {
  std::vector<std::string> rows(30, std::string(60, '.'));
  rows[15] = std::string(60, '#');
  const auto plain = grid_from_text(rows);
  rows[15].replace(28, 6, std::string(6, '.'));
  const auto door = grid_from_text(rows);
  const PreparedGrid a(door), b(door), c(plain);
  const AlignmentQuality right = evaluate_alignment(a, b, core::Transform2::identity());
  EXPECT_GE(right.wall_ends, 2);  // both jambs, at least once
  EXPECT_EQ(evaluate_alignment(a, b, core::Transform2(10.0, 0.0, 0.0)).wall_ends, 0);
  EXPECT_EQ(evaluate_alignment(c, c, core::Transform2::identity()).wall_ends, 0);
}

// A wall that ends in the open (a free-standing partition, a door jamb) seen by both maps: its end
// is counted wherever it falls in the 4 x 4 blocks in which matched walls are sampled (seen on the
// benchmark of robot-built maps: a partition's end both maps saw, not counted, and the pair refused
// as one T).
TEST(AlignmentQuality, CountsAWallEndWhereverItFallsInItsBlock) {
  for (int end = 28; end < 32; ++end) {
    std::vector<std::string> rows(30, std::string(60, '.'));
    rows[15].replace(0, std::size_t(end) + 1, std::string(std::size_t(end) + 1, '#'));
    const auto map = grid_from_text(rows);
    const PreparedGrid a(map), b(map);
    EXPECT_GE(evaluate_alignment(a, b, core::Transform2::identity()).wall_ends, 1) << "wall ending at x = " << end;
  }
}

// One corner of a bare room at 2.5 cm, laid on itself: a straight bottom wall, and a left wall whose
// face is ragged, the first free cell of each row 3 cells either side of its line (a noisy laser at
// fine cells). The ragged face is one wall: nothing lies beyond the corner's two lines. A niche
// 15 cm deep in that wall is a detail off them, at 2.5 cm cells as at 5 cm.
TEST(AlignmentQuality, ARaggedWallFaceIsOneWallAndANicheADetail) {
  for (const double resolution : {0.025, 0.05}) {
    for (const bool niche : {false, true}) {
      const int w = 160, h = 160, wall = 20, floor_y = 20;
      const int depth = int(std::lround(0.15 / resolution));  // the niche's depth, in cells
      mapping::OccupancyGrid g(core::GridGeometry(resolution, w, h));
      core::Random random(7);
      for (int y = floor_y - 6; y < h; ++y) {
        // The first free cell of the row: the face, ragged at 2.5 cm, set back in the niche.
        int face = wall + (resolution < 0.04 ? random.uniform_int(-3, 3) : 0);
        if (niche && y >= 80 && y < 100) face -= depth;
        for (int x = wall - 12; x < w; ++x) {
          const bool occupied = y < floor_y || x < face;
          g.set_state({x, y}, occupied ? mapping::CellState::Occupied : mapping::CellState::Free);
        }
      }
      const PreparedGrid p(g);
      const AlignmentQuality q = evaluate_alignment(p, p, core::Transform2::identity());
      SCOPED_TRACE(::testing::Message() << resolution << " m cells, " << (niche ? "a niche" : "no niche"));
      if (niche) EXPECT_GE(q.beyond_corner, 2);
      else EXPECT_EQ(q.beyond_corner, 0);
      if (!niche && resolution < 0.04) {
        QualityOptions cells_only;
        cells_only.face_band_m = 0.0;  // a line holds the walls within 2 cells only
        EXPECT_GE(evaluate_alignment(p, p, core::Transform2::identity(), cells_only).beyond_corner, 2);
      }
    }
  }
}

// Where the two lines holding most of the matched walls meet: an L (a room's corner: two walls
// ending there, unknown beyond) has two arms, a T (a wall going on past the one that meets it) has
// three. A bare room has no T, so the T tells the place from the room's other corners.
TEST(AlignmentQuality, CountsTheArmsOfTheJunctionOfTheCommonWalls) {
  std::vector<std::string> t(40, std::string(60, '.'));
  for (int y = 0; y < 10; ++y) t[std::size_t(y)] = std::string(60, '?');
  t[10] = std::string(60, '#');
  for (int y = 11; y < 40; ++y) t[std::size_t(y)][25] = '#';
  std::vector<std::string> l = t;
  for (int y = 10; y < 40; ++y) l[std::size_t(y)].replace(0, 25, std::string(25, '?'));
  const auto t_map = grid_from_text(t), l_map = grid_from_text(l);  // outlive the prepared grids
  const PreparedGrid pt(t_map), pl(l_map);
  EXPECT_EQ(evaluate_alignment(pt, pt, core::Transform2::identity()).junction_arms, 3);
  EXPECT_EQ(evaluate_alignment(pl, pl, core::Transform2::identity()).junction_arms, 2);
}

// One rectangular room, 5 x 4 m (walls 2 cells thick, unknown outside), laid on itself: two of its
// four sides run parallel and nothing lies off them, so all its walls say is the room's size. A
// niche in a side puts walls off the sides; a door that both maps see through is an opening they
// share, which fixes where along that side the room is.
TEST(AlignmentQuality, TellsTheSidesOfABareRoomFromWallsWithDetails) {
  const auto room = [](bool niche, bool door) {
    std::vector<std::string> rows(110, std::string(120, '?'));
    const auto fill = [&](int x0, int x1, int r0, int r1, char c) {
      for (int r = r0; r < r1; ++r) rows[std::size_t(r)].replace(std::size_t(x0), std::size_t(x1 - x0), std::size_t(x1 - x0), c);
    };
    fill(8, 112, 10, 94, '#');
    fill(10, 110, 12, 92, '.');
    if (niche) {  // 0.8 m wide, 0.3 m deep, in the bottom side
      fill(48, 68, 92, 100, '#');
      fill(50, 66, 92, 98, '.');
    }
    if (door) {  // 0.9 m wide in the top side, and the corridor behind it
      fill(70, 88, 10, 12, '.');
      fill(60, 100, 0, 10, '.');
    }
    return grid_from_text(rows);
  };
  const auto bare_room = room(false, false), with_niche = room(true, false), with_door = room(false, true);
  const PreparedGrid bare(bare_room), niche(with_niche), door(with_door);
  const auto at_identity = [](const PreparedGrid& g) { return evaluate_alignment(g, g, core::Transform2::identity()); };
  const AlignmentQuality q_bare = at_identity(bare);
  EXPECT_EQ(q_bare.parallel_lines, 2);
  EXPECT_LE(q_bare.off_room_sides, 1);
  EXPECT_EQ(q_bare.common_openings, 0);
  const AlignmentQuality q_niche = at_identity(niche);
  EXPECT_TRUE(q_niche.parallel_lines >= 3 || q_niche.off_room_sides >= 2)
      << q_niche.parallel_lines << " parallel, " << q_niche.off_room_sides << " off the sides";
  EXPECT_EQ(at_identity(door).common_openings, 1);
  // Slid along the door's wall by 2 m, the door lies on the other map's wall: no common opening.
  EXPECT_EQ(evaluate_alignment(door, door, core::Transform2(40.0, 0.0, 0.0)).common_openings, 0);
}

// One room, 5 x 4 m, seen from inside: alone, or with the corridor behind its top wall seen through
// a window, or with a partition 1.5 m long standing out from its bottom wall. A map that saw the room alone has no free cells beyond its sides,
// so its walls tell only the room's size; the partition, reaching more than half a metre in from the walls, says
// where in the room the other map lies. Ragged corners (a block of wall standing out at each) are
// part of the outline, no detail.
TEST(AlignmentQuality, TellsARoomSeenAloneAndTheDetailsInsideIt) {
  const auto room = [](bool corridor, bool partition, bool ragged) {
    std::vector<std::string> rows(110, std::string(120, '?'));
    const auto fill = [&](int x0, int x1, int r0, int r1, char c) {
      for (int r = r0; r < r1; ++r) rows[std::size_t(r)].replace(std::size_t(x0), std::size_t(x1 - x0), std::size_t(x1 - x0), c);
    };
    fill(8, 112, 10, 94, '#');
    fill(10, 110, 12, 92, '.');
    if (corridor) {  // seen through a window in the top wall (glass: no opening on the wall's line)
      fill(20, 100, 0, 9, '.');
      fill(20, 100, 9, 10, '#');
    }
    if (partition) fill(58, 60, 62, 92, '#');
    if (ragged)
      for (const auto& [x, r] : {std::pair(10, 12), std::pair(106, 12), std::pair(10, 88), std::pair(106, 88)}) fill(x, x + 4, r, r + 4, '#');
    return grid_from_text(rows);
  };
  const auto alone_map = room(false, false, true), corridor_map = room(true, false, true), partition_map = room(false, true, true);
  const PreparedGrid alone(alone_map), corridor(corridor_map), partition(partition_map);
  const auto at_identity = [](const PreparedGrid& a, const PreparedGrid& b) {
    return evaluate_alignment(a, b, core::Transform2::identity());
  };
  const AlignmentQuality q_alone = at_identity(alone, alone);
  EXPECT_EQ(q_alone.parallel_lines, 2);
  EXPECT_LE(q_alone.outside_room, 0.02);
  EXPECT_LE(q_alone.room_details, 1);
  EXPECT_GE(q_alone.off_room_sides, 2);  // the ragged corners: not a bare room by its sides alone
  // One of the two maps saw only the room: that is enough.
  EXPECT_LE(at_identity(alone, corridor).outside_room, 0.02);
  EXPECT_LE(at_identity(corridor, alone).outside_room, 0.02);
  EXPECT_GT(at_identity(corridor, corridor).outside_room, 0.02);
  EXPECT_GE(at_identity(partition, partition).room_details, 2);
  EXPECT_LE(at_identity(partition, partition).outside_room, 0.02);
}

}  // namespace
}  // namespace fleetmap::merging
