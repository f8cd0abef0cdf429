#pragma once
// Random numbers and sampling routines of the path tracer. Written here rather than taken from a
// library because each is a few lines and must be bit-for-bit deterministic per pixel and sample
// whatever the thread schedule (pbrt-v4 keeps the same routines in its own util/sampling.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "core/math.h"  // luminance
#include "render/prefetch.h"

namespace dynbench::render {

// PCG32 (O'Neill 2014): small state, good statistics, reproducible streams.
class Random {
 public:
  Random() = default;
  // One independent stream per (seed, frame, pixel, sample): the image does not depend on which
  // thread renders which pixel.
  Random(std::uint64_t seed, std::uint64_t frame, std::uint64_t pixel, std::uint64_t sample) {
    state_ = 0;
    increment_ = (mix(seed ^ mix(frame + 0x9E3779B97F4A7C15ull)) << 1u) | 1u;
    next();
    state_ += mix(pixel * 0x100000001B3ull + sample);
    next();
  }
  // The stream of one path vertex (0: the camera ray, k: the k-th hit) of sample `sample` of
  // `pixel`: each vertex's random numbers depend on its key alone, not on how many numbers the
  // vertices before it drew. Two paths with the same key (the halves of a radiance-change pair,
  // PathTracer::renderChanges) then draw the same numbers at every vertex, even where one half took
  // a branch the other did not (a light-tree pick, Russian roulette) at an earlier vertex.
  static Random vertex(std::uint64_t seed, std::uint64_t frame, std::uint64_t pixel, std::uint64_t sample, std::uint64_t vertex) {
    return Random(mix(seed ^ mix(vertex + 0xD1B54A32D192ED03ull)), frame, pixel, sample);
  }
  std::uint32_t next() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ull + increment_;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  // Uniform in [0, 1).
  double uniform() { return next() * 0x1p-32; }
  glm::dvec2 uniform2() {
    const double a = uniform();
    return {a, uniform()};
  }

 private:
  static std::uint64_t mix(std::uint64_t z) {  // splitmix64's finaliser
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::uint64_t state_ = 0, increment_ = 1;
};


// An orthonormal basis around a unit normal (Duff et al. 2017, "Building an orthonormal basis,
// revisited").
struct Frame {
  glm::dvec3 t, b, n;
  explicit Frame(const glm::dvec3& normal) : n(normal) {
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double c = n.x * n.y * a;
    t = {1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
  }
  glm::dvec3 toLocal(const glm::dvec3& v) const { return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)}; }
  glm::dvec3 toWorld(const glm::dvec3& v) const { return v.x * t + v.y * b + v.z * n; }
};

// Cosine-weighted direction about +Z (Malley's method); pdf = cos(theta) / pi.
inline glm::dvec3 sampleCosineHemisphere(glm::dvec2 u) {
  const double r = std::sqrt(u.x);
  const SinCos phi = sinCosSingle(2.0 * kPi * u.y);
  return {r * phi.cos, r * phi.sin, std::sqrt(std::max(0.0, 1.0 - u.x))};
}

// Uniform point on a triangle, as barycentric weights of vertices 1 and 2 (Heitz 2019's
// low-distortion map would also do; the square-root map is the textbook one).
inline glm::dvec2 sampleTriangle(glm::dvec2 u) {
  const double s = std::sqrt(u.x);
  return {s * (1.0 - u.y), s * u.y};
}

// Walker's alias table (Walker 1977; Vose 1991's construction) over n bins: slot i holds bin i
// with probability `keep` (of the slot's 1/n), else bin `alias`. A sample reads one slot instead of
// a binary search whose every step misses the cache on an environment map's rows (it was the path
// tracer's largest cost in `perf`). pbrt-v4's AliasTable is the same idea.
struct AliasSlot {
  double keep = 1.0;
  std::uint32_t alias = 0;
};
// The table of `weights` (finite, non-negative, summing to total > 0) into `slots` (as many).
void buildAliasTable(std::span<const double> weights, double total, std::span<AliasSlot> slots);
// The slot of `slots` that sampleAlias(slots, u) reads: prefetch it.
inline const AliasSlot& aliasSlotFor(std::span<const AliasSlot> slots, double u) {
  return slots[std::min(static_cast<std::size_t>(std::clamp(u, 0.0, 1.0) * static_cast<double>(slots.size())), slots.size() - 1)];
}
// A bin for u in [0, 1); `remapped` (optional) is uniform in [0, 1) given the bin (what is left of
// u's precision: about 32 - log2(n) bits).
std::size_t sampleAlias(std::span<const AliasSlot> slots, double u, double* remapped);

// A piecewise-constant 1D distribution over n bins of [0, 1) (pbrt's PiecewiseConstant1D), sampled
// in constant time through an alias table.
class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(std::span<const double> weights);
  bool empty() const { return alias_.empty() || total_ <= 0.0; }
  double total() const { return total_; }  // sum of the weights
  std::size_t size() const { return weights_.size(); }
  std::span<const double> weights() const { return weights_; }  // as used: non-finite and negative weights are 0
  // A bin picked with probability weight / total; `remapped` as sampleAlias's.
  std::size_t sampleDiscrete(double u, double* probability = nullptr, double* remapped = nullptr) const;
  double probability(std::size_t bin) const { return total_ > 0 ? weights_[bin] / total_ : 0.0; }
  // Starts loading the table entry sampleDiscrete(u) reads first (its slot and the slot's own bin).
  void prefetch(double u) const;

 private:
  std::vector<double> weights_;
  std::vector<AliasSlot> alias_;
  double total_ = 0.0;
};

// A piecewise-constant 2D distribution over a width x height grid of [0, 1)^2: rows by their
// sums, then a column within the row. Samples a pixel of an environment map by its weight. The
// rows' column tables are one array (row-major), so the slot a column sample reads has an address
// computed from the row alone: with a table per row, finding that table's memory was itself a
// cache miss that the prefetch of its slot had to wait for (perf: 2 % of a render).
class Distribution2D {
 public:
  Distribution2D() = default;
  Distribution2D(std::span<const double> weights, int width, int height);
  bool empty() const { return rows_.empty(); }
  // A continuous point in [0, 1)^2 with its density with respect to area in [0, 1)^2.
  glm::dvec2 sample(glm::dvec2 u, double* density) const;
  // The same point, and the index (row x width + column) of its cell instead of the density.
  glm::dvec2 sampleCell(glm::dvec2 u, std::size_t* cell) const;
  double density(glm::dvec2 point) const;
  // sampleCell in two steps, so that a batched caller can load the column table entry between
  // them: the row (from the row table, which is small and stays cached) with what is left of
  // u.y, then the column. sampleColumn(sampleRow(u.y), u.x, cell) is sampleCell(u, cell).
  struct RowSample {
    std::size_t row = 0;
    double v = 0.0;  // uniform in [0, 1) within the row
  };
  RowSample sampleRow(double uy) const;
  void prefetchColumn(const RowSample& row, double ux) const { prefetchLine(&aliasSlotFor(columnsOf(row.row), ux)); }
  glm::dvec2 sampleColumn(const RowSample& row, double ux, std::size_t* cell) const;

 private:
  double cellDensity(std::size_t row, std::size_t column) const;
  std::span<const AliasSlot> columnsOf(std::size_t row) const {
    return std::span(columnSlots_).subspan(row * static_cast<std::size_t>(width_), static_cast<std::size_t>(width_));
  }

  int width_ = 0, height_ = 0;
  Distribution1D rows_;          // by row sums
  std::vector<double> weights_;  // per cell, as used (non-finite and negative weights are 0)
  std::vector<AliasSlot> columnSlots_;  // per row, the alias table of its columns
};

// The power heuristic with beta = 2 (Veach 1997, eq. 9.13): weight of a sample of strategy f.
inline double powerHeuristic(double pdfF, double pdfG) {
  const double f = pdfF * pdfF, g = pdfG * pdfG;
  return f + g > 0.0 ? f / (f + g) : 0.0;
}

}  // namespace dynbench::render
