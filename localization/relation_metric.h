#pragma once
// The relation metric of Kümmerle et al. 2009 ("On measuring the accuracy of SLAM algorithms"):
// the error of an estimated trajectory is measured on relative motions between pairs of its poses,
// against reference relations, so that a trajectory is judged by its local consistency and no
// global frame or alignment is needed.
#include <cstddef>
#include <vector>

#include "core/transform2.h"

namespace fleetmap::localization {

// A pose of the estimated trajectory at a scan's time.
struct TimedPose {
  double time_s = 0.0;
  core::Pose2 pose;
};

// A reference relation: the true motion from the pose at `t1` to the pose at `t2`, in the frame
// of the first. A trajectory pose belongs to a time when it is within the tolerance of it.
struct ReferenceRelation {
  double t1 = 0.0, t2 = 0.0;
  double t1_tolerance = 0.0, t2_tolerance = 0.0;
  core::Pose2 motion;
};

struct RelationErrors {
  std::size_t relations = 0;  // given
  std::size_t matched = 0;    // whose two times matched a pose each
  // Over the matched relations (Kümmerle et al. 2009, eq. (2)-(3), unsquared): the translational
  // error |t(est) - t(true)| (m) and the absolute rotational error |angle(est) - angle(true)| (rad),
  // with est = inv(pose(t1)) * pose(t2). Means and population standard deviations.
  double translation_mean_m = 0.0, translation_std_m = 0.0;
  double rotation_mean_rad = 0.0, rotation_std_rad = 0.0;
  // Per relation, in order: whether it matched.
  std::vector<bool> matched_each;
};

// `trajectory` sorted by time (a time that falls within two poses' tolerance takes the nearest).
RelationErrors relation_errors(const std::vector<TimedPose>& trajectory, const std::vector<ReferenceRelation>& relations);

}  // namespace fleetmap::localization
