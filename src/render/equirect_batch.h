#pragma once
// core/math.h's equirectangular mapping for a batch of image points or directions at once, several
// per SIMD instruction (Google's Highway, as in bsdf_batch.h; it picks SSE4, AVX2 or AVX-512 at run
// time). The batched path tracer maps its environment light samples' image points to directions,
// and its escaped rays' directions to image points, here: one glibc sincosf or atan2 call at a
// time, they were 6 % of a render's time (perf).
//
// In double precision: a lane agrees with equirectDirection and equirectCoordinates to a few ulp
// (Highway's sine, cosine and arc tangent are within 3 ulp), not bit for bit (render_test.cpp:
// `EquirectBatch.*`). Lanes are independent.
#include <cstddef>

#include <glm/glm.hpp>

#include "render/lane_arrays.h"

namespace dynbench::render {

class EquirectBatch {
 public:
  // Room for `lanes` points or directions (LaneArrays). Growing discards them.
  void reserve(std::size_t lanes) { lanes_.reserve(lanes); }

  // Image point -> unit direction and sin(theta) (equirectDirection), for lanes [0, count).
  void setPoint(std::size_t lane, glm::dvec2 uv);
  void directions(std::size_t count);
  glm::dvec3 direction(std::size_t lane, double* sinTheta) const;

  // Direction -> image point and sin(theta) (equirectCoordinates), for lanes [0, count).
  void setDirection(std::size_t lane, const glm::dvec3& direction);
  void coordinates(std::size_t count);
  glm::dvec2 point(std::size_t lane, double* sinTheta) const;

  // The arrays, one per quantity, each `capacity` lanes long (structure of arrays).
  enum Field : std::size_t { kU, kV, kX, kY, kZ, kSinTheta, kFieldCount };

 private:
  double& at(Field f, std::size_t lane) { return lanes_.at(f, lane); }
  double at(Field f, std::size_t lane) const { return lanes_.at(f, lane); }
  LaneArrays<kFieldCount> lanes_;
};

}  // namespace dynbench::render
