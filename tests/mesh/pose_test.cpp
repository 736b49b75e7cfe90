#include <cmath>
#include <limits>
#include <vector>
#include <string>

#include <gtest/gtest.h>

#include "caliber/batch.h"
#include "caliber/error.h"
#include "caliber/mesh.h"
#include "caliber/pose.h"
#include "caliber/query.h"

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

TEST(Pose, FromAMatrixAndAnIsometry) {
  const Pose p = Pose::from_values(1, -2, 3, 0.9, 0.1, -0.3, 0.2);
  const Pose q = Pose::from_matrix(p.matrix());
  EXPECT_LT((q.matrix() - p.matrix()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LT(q.rotation.angularDistance(p.rotation), 1e-15);
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  iso.linear() = p.rotation_matrix();
  iso.translation() = p.translation;
  EXPECT_LT((Pose::from_isometry(iso).matrix() - p.matrix()).cwiseAbs().maxCoeff(), 1e-15);
  // A rotation rounded to floats is a rotation within 1e-6, not within 1e-9.
  const Eigen::Matrix4d rounded = p.matrix().cast<float>().cast<double>();
  EXPECT_THROW((void)Pose::from_matrix(rounded), Error);
  EXPECT_LT((Pose::from_matrix(rounded, 1e-6).matrix() - p.matrix()).cwiseAbs().maxCoeff(), 1e-6);
  const auto message = [](const Eigen::Matrix4d& m) {
    try {
      (void)Pose::from_matrix(m, 1e-9, "pose of the arm");
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::bad_value);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  Eigen::Matrix4d scaled = Eigen::Matrix4d::Identity();
  scaled(0, 0) = 2.0;
  EXPECT_NE(message(scaled).find("pose of the arm: is not a rigid transform"), std::string::npos) << message(scaled);
  Eigen::Matrix4d mirror = Eigen::Matrix4d::Identity();
  mirror(2, 2) = -1.0;
  EXPECT_NE(message(mirror).find("det R = -1"), std::string::npos) << "a mirror image is no rotation: " << message(mirror);
  Eigen::Matrix4d projective = Eigen::Matrix4d::Identity();
  projective(3, 0) = 0.5;
  EXPECT_NE(message(projective).find("last row"), std::string::npos);
  Eigen::Matrix4d nan = Eigen::Matrix4d::Identity();
  nan(1, 3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(nan).find("not finite"), std::string::npos);
  Eigen::Matrix4d far = Eigen::Matrix4d::Identity();
  far(0, 3) = 1e300;
  EXPECT_NE(message(far).find("1e15"), std::string::npos) << "the translation's limits hold too: " << message(far);
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

TEST(Pose, ABadRotationToleranceIsNamedEvenWithoutMatrices) {
  for (const std::size_t count : {0u, 16u}) {
    const std::vector<double> values(count, 0.0);
    try {
      (void)poses_from_matrices(values, std::numeric_limits<double>::quiet_NaN(), "poses");
      FAIL() << "a NaN tolerance was taken";
    } catch (const Error& e) {
      EXPECT_EQ(e.source(), "tolerance") << e.what();
    }
  }
}

TEST(Pose, HugeQuaternionsDoNotOverflowIntoAZeroRotation) {
  // Squaring 1e200 overflows; the quaternion is scaled first (found while writing the pose fuzzer).
  const Pose p = Pose::from_values(0, 0, 0, 1e200, 0, 0, 1e200);
  EXPECT_NEAR(p.rotation.w(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(p.rotation.z(), std::sqrt(0.5), 1e-15);
  EXPECT_NO_THROW(validate_pose(p));
  const Pose tiny = Pose::from_values(0, 0, 0, 0, 3e-9, 4e-9, 0);
  EXPECT_NEAR(tiny.rotation.x(), 0.6, 1e-15);
  EXPECT_THROW((void)Pose::from_values(0, 0, 0, 1e-12, 0, 0, 0), Error) << "nearly zero";
}

TEST(Limits, CoordinatesBeyondTheLimitAreErrors) {
  EXPECT_NO_THROW((void)Pose::from_values(kMaxCoordinate, 0, 0, 1, 0, 0, 0));
  EXPECT_THROW((void)Pose::from_values(0, -2e15, 0, 1, 0, 0, 0), Error);
  EXPECT_THROW((void)parse_pose("1e300 0 0 1 0 0 0"), Error);
  Pose p;
  p.translation.z() = 1e16;
  EXPECT_THROW(validate_pose(p), Error);
  QueryRequest request;
  request.kind = QueryKind::proximity;
  request.tolerance = 1e16;
  EXPECT_THROW(validate_request(request), Error);
  Mesh mesh;
  mesh.source = "hand-built";
  mesh.vertices = {{0, 0, 0}, {1e15, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  EXPECT_NO_THROW(validate_mesh(mesh));
  try {
    scale_mesh(mesh, 10.0);
    FAIL() << "scaling beyond the limit must fail";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 1"), std::string::npos) << e.what();
  }
  EXPECT_EQ(mesh.vertices[1].x(), 1e15) << "a failed scale leaves the mesh as it was";
  mesh.vertices[2].y() = -1.5e15;
  EXPECT_THROW(validate_mesh(mesh), Error);
}

}  // namespace
}  // namespace caliber
