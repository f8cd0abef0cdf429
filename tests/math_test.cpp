// Known answers for the rotation math behind Tables 6.5 and 6.6.
#include <gtest/gtest.h>

#include "core/math.h"

namespace dynbench {
namespace {

constexpr double kTol = 1e-9;

TEST(Geodesic, QuarterTurnIsNinetyDegrees) {
  const glm::dquat a(1, 0, 0, 0);
  const glm::dquat b = glm::angleAxis(radians(90.0), glm::dvec3(0, 0, 1));
  EXPECT_NEAR(degrees(geodesicAngle(a, b)), 90.0, kTol);
}

TEST(Geodesic, SignFlipIsTheSameRotation) {
  const glm::dquat q = glm::angleAxis(radians(37.0), glm::normalize(glm::dvec3(1, 2, 3)));
  EXPECT_NEAR(geodesicAngle(q, -q), 0.0, kTol);
  EXPECT_NEAR(geodesicAngle(q, q), 0.0, kTol);
}

TEST(Geodesic, RelativeToNonIdentityStart) {
  // 30 deg about X after an arbitrary rotation: still 30 deg apart.
  const glm::dquat start = glm::angleAxis(radians(123.0), glm::normalize(glm::dvec3(-1, 0.5, 2)));
  const glm::dquat end = start * glm::angleAxis(radians(30.0), glm::dvec3(1, 0, 0));
  EXPECT_NEAR(degrees(geodesicAngle(start, end)), 30.0, 1e-7);
  // and a negated end does not change it
  EXPECT_NEAR(degrees(geodesicAngle(start, -end)), 30.0, 1e-7);
}

TEST(Geodesic, HalfTurnIs180) {
  const glm::dquat b = glm::angleAxis(radians(180.0), glm::dvec3(0, 1, 0));
  EXPECT_NEAR(degrees(geodesicAngle(glm::dquat(1, 0, 0, 0), b)), 180.0, 1e-7);
}

TEST(Euler, RoundTripsGameCameraAngles) {
  for (double yaw : {-170.0, -45.0, 0.0, 30.0, 179.0})
    for (double pitch : {-80.0, -10.0, 0.0, 45.0, 89.0})
      for (double roll : {-120.0, 0.0, 5.0, 170.0}) {
        const auto e = eulerYawPitchRoll(quatFromYawPitchRoll(radians(yaw), radians(pitch), radians(roll)));
        EXPECT_NEAR(degrees(e.yaw), yaw, 1e-6) << yaw << " " << pitch << " " << roll;
        EXPECT_NEAR(degrees(e.pitch), pitch, 1e-6);
        EXPECT_NEAR(degrees(e.roll), roll, 1e-6);
      }
}

TEST(Euler, PositiveYawTurnsLeftAndPositivePitchLooksUp) {
  // A camera looks down -Z. Yaw +90 about +Y turns -Z into -X (left, seen from above).
  const glm::dvec3 forward(0, 0, -1);
  const glm::dvec3 afterYaw = glm::mat3_cast(quatFromYawPitchRoll(radians(90.0), 0, 0)) * forward;
  EXPECT_NEAR(afterYaw.x, -1.0, kTol);
  const glm::dvec3 afterPitch = glm::mat3_cast(quatFromYawPitchRoll(0, radians(30.0), 0)) * forward;
  EXPECT_NEAR(afterPitch.y, 0.5, kTol);  // sin 30
}

TEST(Euler, GimbalLockPutsEverythingInYaw) {
  const auto e = eulerYawPitchRoll(quatFromYawPitchRoll(radians(40.0), radians(90.0), 0.0));
  EXPECT_NEAR(degrees(e.pitch), 90.0, 1e-4);
  EXPECT_NEAR(degrees(e.yaw), 40.0, 1e-4);
  EXPECT_NEAR(e.roll, 0.0, kTol);
}

TEST(WrapDegrees, AcrossTheSeam) {
  EXPECT_NEAR(wrapDegrees(-179.0 - 179.0), 2.0, kTol);
  EXPECT_NEAR(wrapDegrees(179.0 - -179.0), -2.0, kTol);
  EXPECT_NEAR(wrapDegrees(180.0), 180.0, kTol);
  EXPECT_NEAR(wrapDegrees(-180.0), 180.0, kTol);
  EXPECT_NEAR(wrapDegrees(725.0), 5.0, kTol);
}

TEST(DecomposeRigid, RemovesScaleAndMirror) {
  const glm::dquat r = glm::angleAxis(radians(50.0), glm::dvec3(0, 1, 0));
  glm::dmat4 m = glm::mat4_cast(r);
  m[0] *= 3.0;
  m[1] *= 0.5;
  m[2] *= 2.0;
  m[3] = glm::dvec4(1, 2, 3, 1);
  const RigidPose pose = decomposeRigid(m);
  EXPECT_NEAR(geodesicAngle(pose.rotation, r), 0.0, 1e-9);
  EXPECT_EQ(pose.position, glm::dvec3(1, 2, 3));
}

}  // namespace
}  // namespace dynbench
