#pragma once
// Rotation math for camera-motion metrics. Linear algebra itself comes from GLM (libglm-dev);
// only the conventions that the thesis's metrics need are written here.
//
// Conventions (docs/metrics.md): right-handed, +Y up, a camera looks down its local -Z with +Y up
// (glTF §3.10). Angles in this header are radians unless the name says Degrees.
#include <array>
#include <cmath>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace dynbench {

inline constexpr double kPi = 3.14159265358979323846;
inline double degrees(double radians) { return radians * (180.0 / kPi); }
inline double radians(double degrees) { return degrees * (kPi / 180.0); }

// Position and orientation of a world matrix with scale (and shear) removed.
struct RigidPose {
  glm::dvec3 position{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // glm order: (w, x, y, z)
};

// Rotation part of an affine matrix: columns normalised; a mirrored basis (det < 0) has its
// X column negated so that the result is a proper rotation.
RigidPose decomposeRigid(const glm::dmat4& world);

// Thesis Eq. (2.4): d_r = || ln(q_{i-1}^{-1} q_i) ||. For a unit quaternion q = (cos(θ/2), u sin(θ/2))
// ln q = u θ/2, so Eq. (2.4) is half the rotation angle θ. We return θ itself, in [0, π]: the angle
// a viewer sees the camera turn (docs/metrics.md). The relative rotation is taken on the shortest
// arc, so q and -q (the same rotation) give 0.
double geodesicAngle(const glm::dquat& previous, const glm::dquat& current);

// Game-camera Euler angles (docs/metrics.md): R = Ry(yaw) * Rx(pitch) * Rz(roll), applied to a camera
// that looks down -Z with +Y up. yaw turns about world +Y (positive turns left, counter-clockwise seen
// from above), pitch about the camera's X axis after yaw (positive looks up), roll about the viewing
// axis last (positive rolls the camera counter-clockwise about +Z, its backward axis).
// Ranges: yaw, roll in (-π, π]; pitch in [-π/2, π/2]. At pitch ±90° roll is set to 0.
struct EulerYawPitchRoll {
  double yaw = 0.0;
  double pitch = 0.0;
  double roll = 0.0;
};
EulerYawPitchRoll eulerYawPitchRoll(const glm::dquat& rotation);
glm::dquat quatFromYawPitchRoll(double yaw, double pitch, double roll);

// A rigid transform as a unit dual quaternion (thesis §2.2): real = rotation r, dual = ½ (t, 0) r.
struct DualQuaternion {
  glm::dquat real{1.0, 0.0, 0.0, 0.0};
  glm::dquat dual{0.0, 0.0, 0.0, 0.0};
};
DualQuaternion dualQuaternionFromRigid(const glm::dquat& rotation, const glm::dvec3& translation);
// Rotation (normalised real part) and translation t = 2 d r* (r normalised first, d scaled alike).
glm::dquat rotationOf(const DualQuaternion& q);
glm::dvec3 translationOf(const DualQuaternion& q);
glm::dmat4 matrixOf(const DualQuaternion& q);

// Wraps an angle difference in degrees into (-180, 180], so a yaw going from 179° to -179° changes
// by 2°, not 358°.
double wrapDegrees(double degreesValue);

// The Catmull-Rom spline's weights of the four samples around t in [0, 1) (Keys' cubic, a = -0.5):
// interpolating, exact on quadratics, summing to 1.
inline std::array<double, 4> catmullRomWeights(double t) {
  const double t2 = t * t, t3 = t2 * t;
  return {0.5 * (-t3 + 2.0 * t2 - t), 0.5 * (3.0 * t3 - 5.0 * t2 + 2.0), 0.5 * (-3.0 * t3 + 4.0 * t2 + t), 0.5 * (t3 - t2)};
}

// Luminance of linear Rec.709 RGB (ITU-R BT.709 Y): the one scalar the renderer's variance
// channels, light choice and the discard's noise test use.
inline double luminance(const glm::dvec3& rgb) { return 0.2126 * rgb.r + 0.7152 * rgb.g + 0.0722 * rgb.b; }

// The sRGB transfer function decoded (IEC 61966-2-1): an sRGB-encoded channel in [0, 1] to linear.
// In the channel's own precision (float for textures, double for ꟻLIP and fidelity), so each caller
// computes exactly what it did with its own copy.
template <typename T>
inline T srgbToLinear(T c) {
  return c <= T(0.04045) ? c / T(12.92) : std::pow((c + T(0.055)) / T(1.055), T(2.4));
}
// Its inverse: a linear channel in [0, 1] to sRGB-encoded.
template <typename T>
inline T linearToSrgb(T c) {
  return c <= T(0.0031308) ? T(12.92) * c : T(1.055) * std::pow(c, T(1) / T(2.4)) - T(0.055);
}

// sin and cos of an angle, computed in single precision and widened. For Monte Carlo sampling
// only: a sampled direction is off by at most ~3e-7 rad (the float rounding of the angle), far
// below a pixel of any image here, and the sample's density is computed from the direction
// produced, so nothing is biased. glibc's sincosf takes about 8 ns here against 18 ns for sincos.
// (The batched path tracer's own sines and cosines are Highway's, in double precision:
// render/bsdf_batch.h, render/equirect_batch.h.)
struct SinCos {
  double sin = 0.0, cos = 1.0;
};
inline SinCos sinCosSingle(double angle) {
  const float a = static_cast<float>(angle);
  return {std::sin(a), std::cos(a)};  // one sincosf call (GCC merges the pair)
}

// The equirectangular mapping of dataset environments (docs/dataset.md): image point (u, v) in
// [0, 1]² to a unit direction; u = 0.5 looks down -Z, u grows towards +X; v = 0 is straight up (+Y).
glm::dvec3 equirectDirection(double u, double v);
// The same, also giving sin(theta) = sin(pi v) (the mapping's Jacobian needs it).
glm::dvec3 equirectDirection(double u, double v, double* sinTheta);
// Its inverse: the image point a unit direction maps to.
glm::dvec2 equirectCoordinates(const glm::dvec3& direction);
// The same, also giving sin(theta) = sin(pi v), from the direction itself (no sine to compute).
glm::dvec2 equirectCoordinates(const glm::dvec3& direction, double* sinTheta);
// Solid angle of pixel row `row` of an equirectangular image of the given size, steradians.
double equirectPixelSolidAngle(int row, int width, int height);

}  // namespace dynbench
