#include "core/math.h"

#include <algorithm>
#include <cmath>

namespace dynbench {

RigidPose decomposeRigid(const glm::dmat4& world) {
  RigidPose pose;
  pose.position = glm::dvec3(world[3]);
  glm::dvec3 x(world[0]), y(world[1]), z(world[2]);
  const double lx = glm::length(x), ly = glm::length(y), lz = glm::length(z);
  // A zero-scaled node has no orientation; keep identity rather than dividing by zero.
  if (lx <= 0.0 || ly <= 0.0 || lz <= 0.0) return pose;
  x /= lx;
  y /= ly;
  z /= lz;
  if (glm::dot(glm::cross(x, y), z) < 0.0) x = -x;
  pose.rotation = glm::normalize(glm::quat_cast(glm::dmat3(x, y, z)));
  return pose;
}

double geodesicAngle(const glm::dquat& previous, const glm::dquat& current) {
  const glm::dquat relative = glm::conjugate(glm::normalize(previous)) * glm::normalize(current);
  const double vectorLength =
      std::sqrt(relative.x * relative.x + relative.y * relative.y + relative.z * relative.z);
  // atan2 is accurate for tiny and near-π angles where acos(w) is not; |w| picks the shortest arc.
  return 2.0 * std::atan2(vectorLength, std::abs(relative.w));
}

EulerYawPitchRoll eulerYawPitchRoll(const glm::dquat& rotation) {
  const glm::dmat3 m = glm::mat3_cast(glm::normalize(rotation));
  // glm is column-major: m[col][row]. With R = Ry(ψ) Rx(θ) Rz(φ):
  //   R(1,2) = -sin θ,  R(0,2) = sin ψ cos θ,  R(2,2) = cos ψ cos θ,
  //   R(1,0) = cos θ sin φ,  R(1,1) = cos θ cos φ.
  auto at = [&](int row, int col) { return m[col][row]; };
  EulerYawPitchRoll e;
  const double sinPitch = std::clamp(-at(1, 2), -1.0, 1.0);
  e.pitch = std::asin(sinPitch) + 0.0;  // + 0.0 turns -0 into 0 for tidy output
  const double cosPitch = std::sqrt(at(0, 2) * at(0, 2) + at(2, 2) * at(2, 2));
  if (cosPitch > 1e-9) {
    e.yaw = std::atan2(at(0, 2), at(2, 2));
    e.roll = std::atan2(at(1, 0), at(1, 1));
  } else {
    // Gimbal lock (looking straight up or down): yaw and roll share one axis; put it all in yaw.
    // With φ = 0: R(0,0) = cos ψ, R(2,0) = -sin ψ.
    e.yaw = std::atan2(-at(2, 0), at(0, 0));
    e.roll = 0.0;
  }
  return e;
}

glm::dquat quatFromYawPitchRoll(double yaw, double pitch, double roll) {
  return glm::angleAxis(yaw, glm::dvec3(0, 1, 0)) * glm::angleAxis(pitch, glm::dvec3(1, 0, 0)) *
         glm::angleAxis(roll, glm::dvec3(0, 0, 1));
}

DualQuaternion dualQuaternionFromRigid(const glm::dquat& rotation, const glm::dvec3& translation) {
  const glm::dquat r = glm::normalize(rotation);
  return {r, 0.5 * (glm::dquat(0.0, translation.x, translation.y, translation.z) * r)};
}

glm::dquat rotationOf(const DualQuaternion& q) { return glm::normalize(q.real); }

glm::dvec3 translationOf(const DualQuaternion& q) {
  const double n = glm::length(q.real);
  const glm::dquat t = 2.0 * (q.dual / n) * glm::conjugate(q.real / n);
  return {t.x, t.y, t.z};
}

glm::dmat4 matrixOf(const DualQuaternion& q) {
  glm::dmat4 m = glm::mat4_cast(rotationOf(q));
  m[3] = glm::dvec4(translationOf(q), 1.0);
  return m;
}

double wrapDegrees(double d) {
  double w = std::fmod(d, 360.0);
  if (w <= -180.0) w += 360.0;
  if (w > 180.0) w -= 360.0;
  return w;
}

glm::dvec3 equirectDirection(double u, double v) {
  double sinTheta = 0.0;
  return equirectDirection(u, v, &sinTheta);
}

glm::dvec3 equirectDirection(double u, double v, double* sinTheta) {
  const double phi = 2.0 * kPi * (u - 0.5);  // azimuth from -Z towards +X
  const double theta = kPi * v;              // polar angle from +Y
  *sinTheta = std::sin(theta);
  return {*sinTheta * std::sin(phi), std::cos(theta), -*sinTheta * std::cos(phi)};
}

glm::dvec2 equirectCoordinates(const glm::dvec3& d) {
  double sinTheta = 0.0;
  return equirectCoordinates(d, &sinTheta);
}

glm::dvec2 equirectCoordinates(const glm::dvec3& d, double* sinTheta) {
  const double phi = std::atan2(d.x, -d.z);
  // atan2 rather than acos(d.y): acos loses half the digits near the poles.
  const double horizontal = std::sqrt(d.x * d.x + d.z * d.z);
  const double theta = std::atan2(horizontal, d.y);
  const double length = std::sqrt(horizontal * horizontal + d.y * d.y);
  *sinTheta = length > 0 ? horizontal / length : 0.0;
  return {phi / (2.0 * kPi) + 0.5, theta / kPi};
}

double equirectPixelSolidAngle(int row, int width, int height) {
  const double theta0 = kPi * row / height, theta1 = kPi * (row + 1) / height;
  return (2.0 * kPi / width) * (std::cos(theta0) - std::cos(theta1));
}

}  // namespace dynbench
