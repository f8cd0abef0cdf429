#pragma once
// Bsdf::evaluate and Bsdf::sample for a batch of path vertices at once, several per SIMD
// instruction (Google's Highway, wrapped here and nowhere else; it picks SSE4, AVX2 or AVX-512 at
// run time). The batched path tracer shades its paths one at a time but evaluates their BSDFs
// here: the scalar code, two evaluations and a sample per shading point in double precision, was
// a fifth of the frame time (docs/feature-buffers.md, "Speed").
//
// Each lane computes what Bsdf computes for the same vertex, in the same double precision, up to
// rounding: the order of a few operations and the sine and cosine (Highway's, 3 ulp, against
// glibc's single-precision sincosf in Bsdf) differ, so results agree to about 1e-7 relative, not
// bit for bit (render_test.cpp: `BsdfBatch.*`). Lanes are independent: a lane's result does not
// depend on the other lanes or on how many there are.
#include <cstddef>

#include <glm/glm.hpp>

#include "render/bsdf.h"
#include "render/lane_arrays.h"

namespace dynbench::render {

class BsdfBatch {
 public:
  // Room for `lanes` vertices (LaneArrays). Growing discards the lanes' contents.
  void reserve(std::size_t lanes) { lanes_.reserve(lanes); }
  std::size_t capacity() const { return lanes_.capacity(); }

  // Lane `lane`: the vertex's BSDF, Bsdf(material, Frame(shadingNormal), geometricNormal), seen
  // from wo (Bsdf::view; the kernel builds both); the direction whose value and pdf to evaluate
  // (Bsdf::evaluate), if any; and the random numbers of the sample (Bsdf::sample).
  void set(std::size_t lane, const SurfaceMaterial& material, const glm::dvec3& shadingNormal, const glm::dvec3& geometricNormal,
           const glm::dvec3& wo);
  void setEvaluation(std::size_t lane, const glm::dvec3& wi);
  void clearEvaluation(std::size_t lane);
  void setSample(std::size_t lane, glm::dvec2 u, double uLobe);

  // Both, for lanes [0, count).
  void run(std::size_t count);

  // Results: the evaluation (zero where none was asked for); the sample, false where Bsdf::sample
  // gives none.
  Bsdf::Evaluation evaluation(std::size_t lane) const;
  bool sample(std::size_t lane, BsdfSample& out) const;

  // The arrays, one per quantity, each `capacity` lanes long (structure of arrays).
  enum Field : std::size_t {
    kNx, kNy, kNz,                                 // shading normal
    kGx, kGy, kGz,                                 // geometric normal
    kBaseR, kBaseG, kBaseB, kMetallic, kRoughness, kSpecular,  // material
    kSpecularR, kSpecularG, kSpecularB,            // KHR_materials_specular's colour
    kWoX, kWoY, kWoZ,                              // towards the viewer (world)
    kWiX, kWiY, kWiZ, kEvaluate,                  // direction to evaluate (world), and whether to
    kU1, kU2, kULobe,                             // the sample's random numbers
    kValueR, kValueG, kValueB, kPdf,              // evaluation out
    kDirX, kDirY, kDirZ, kSampleR, kSampleG, kSampleB, kSamplePdf,  // sample out (pdf 0: none)
    kFieldCount
  };

 private:
  double& at(Field f, std::size_t lane) { return lanes_.at(f, lane); }
  double at(Field f, std::size_t lane) const { return lanes_.at(f, lane); }
  LaneArrays<kFieldCount> lanes_;
};

}  // namespace dynbench::render
