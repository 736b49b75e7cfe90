#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "caliber/error.h"
#include "caliber/pose.h"

namespace caliber {
namespace {

TEST(Pose, ParsesSevenNumbers) {
  const Pose p = parse_pose("1 2 3 1 0 0 0");
  EXPECT_EQ(p.translation, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(p.rotation.w(), 1.0);
  const Pose q = parse_pose("1,2,3, 0,0,0,1");
  EXPECT_EQ(q.rotation.z(), 1.0);
}

TEST(Pose, NormalizesTheQuaternion) {
  const Pose p = parse_pose("0 0 0 2 0 0 0");
  EXPECT_DOUBLE_EQ(p.rotation.norm(), 1.0);
  const Pose q = parse_pose("0 0 0 1 1 1 1");
  EXPECT_NEAR(q.rotation.norm(), 1.0, 1e-15);
  EXPECT_NO_THROW(validate_pose(q));
}

TEST(Pose, RejectsBadText) {
  EXPECT_THROW((void)parse_pose("1 2 3"), Error);
  EXPECT_THROW((void)parse_pose("1 2 3 1 0 0 0 9"), Error);
  EXPECT_THROW((void)parse_pose("1 2 x 1 0 0 0"), Error);
  EXPECT_THROW((void)parse_pose(""), Error);
  EXPECT_THROW((void)parse_pose("nan 0 0 1 0 0 0"), Error);
  EXPECT_THROW((void)parse_pose("0 0 0 inf 0 0 0"), Error);
  EXPECT_THROW((void)parse_pose("0 0 0 0 0 0 0"), Error);
  EXPECT_THROW((void)parse_pose("0 0 0 1e-300 0 0 0"), Error);
  try {
    (void)parse_pose("0 0 0 0 0 0 0", "--pose-b");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--pose-b"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("zero"), std::string::npos);
  }
}

TEST(Pose, ValidateRejectsHandBuiltBadPoses) {
  Pose p;
  p.rotation = Eigen::Quaterniond(2, 0, 0, 0);
  EXPECT_THROW(validate_pose(p), Error);
  p.rotation = Eigen::Quaterniond::Identity();
  p.translation.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(validate_pose(p), Error);
}

}  // namespace
}  // namespace caliber
