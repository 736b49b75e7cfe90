#pragma once
/// \file
/// validate_pose for many poses: the pose's name is made only when it is bad.

#include <string_view>

#include "caliber/error.h"
#include "caliber/pose.h"

namespace caliber {

/// validate_pose(pose, source()), with source() called only for a bad pose (a good one makes no
/// string: a frame checks one pose per object at every step).
template <class Source>
void validate_pose_named(const Pose& pose, Source&& source) {
  try {
    validate_pose(pose, std::string_view());
  } catch (const Error&) {
    validate_pose(pose, source());  // throws again, naming the pose
  }
}

}  // namespace caliber
