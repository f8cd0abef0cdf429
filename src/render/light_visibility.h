#pragma once
// What the light tree cannot see: walls. The tree's importance (light_tree.h) bounds what each
// node's lights would send a point with nothing in between; in id Tech 3 and Cube 2 maps, rooms and
// corridors, most lights in reach by distance and orientation are behind a wall, so most of the
// tree's picks were shadow rays that found nothing. A frame's LightVisibility learns, before the
// frame is rendered, which lights' light arrives, per cell of a hash grid over surface points (and
// the axis their normal faces): a light is *seen* in a cell where its shadow ray arrived at one of
// the cell's pilot points. At a shading point the direct light is then split in two sums over the
// lights that can reach it (LightSet::selectPunctual):
//   - the cell's seen lights, every one evaluated (probability 1: no selection noise where light
//     is known to arrive, the bulk of it);
//   - the others, sampled by the tree with each node's importance multiplied by
//       f = 0 where every light below is seen (counted in the first sum),
//           1 where some light below is unseen and reached no pilot point of the cell (nothing
//             learned of it),
//           s = kDefensiveShare otherwise (its light reached pilot points unoccluded, never arrived).
// Every light not seen keeps a non-zero probability wherever it can reach a point, and each light
// is in exactly one of the two sums, so the estimate stays unbiased: a defensive mixture in the
// spirit of Vévoda et al. 2018, "Bayesian online regression for adaptive direct illumination
// sampling", with the lights learned to arrive taken out of the sampling altogether. (Until
// 2026-11-30 the seen lights were sampled too, by f = s + (1 - s) A / U: on v2's oa_dm1 frame 108
// evaluating them instead cut the direct light's variance by a factor of many; docs/feature-buffers.md,
// "Every light in reach".)
//
// Cells come in kLevels sizes, each twice the one before: a shading point takes the smallest cell
// around it that holds at least kMinPoints pilot points (else the largest that holds any), so
// surfaces the pilot saw densely get fine factors and those it saw sparsely (far away, or reached
// only by bounces) coarse ones.
//
// Deterministic: the pilot points are fixed by the frame (PathTracer::learnLightVisibility: camera
// rays through a lattice of pixel centres and one cosine bounce each, from a stream of their own),
// their shadow rays are traced in parallel into per-point slots, and the sums are made cell by cell
// in point order, so the factors do not depend on threads or their schedule.
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "render/lights.h"

namespace dynbench::render {

class LightVisibility {
 public:
  // The share of a node's importance kept where nothing of its light was seen to arrive.
  static constexpr double kDefensiveShare = 0.1;
  static constexpr int kLevels = 5;
  static constexpr std::uint32_t kMinPoints = 4;
  static constexpr std::size_t kMaxReachLeaves = 64;

  // A pilot point: a surface point and the unit normal of its side facing the ray that found it.
  struct Point {
    glm::dvec3 position{0.0}, normal{0.0};
  };
  // Whether the shadow ray from pilot point `point` towards the light of `sample` arrives.
  using Visible = std::function<bool(const Point& point, const LightSample& sample)>;

  // Learns from `points` (in their order) on `lights`' tree: at each point, every point or spot
  // light the tree says can reach it gives U = luminance(irradiance) cos (LightSet::samplePunctual)
  // and, where `visible`, A = U. Cells are cubes of side `cellSize` (world units), split by the axis
  // and side the normal mostly faces (the smallest level's; the others' are 2, 4, ... times it).
  void learn(const LightSet& lights, std::span<const Point> points, double cellSize, const Visible& visible);

  // What was learned for the cell holding a shading point.
  struct Cell {
    const float* factors = nullptr;          // one per tree node (above); nullptr: no pilot point fell in a cell here
    std::span<const std::uint32_t> seen;     // the seen lights (tree light indices, ascending)
    std::uint32_t typicalReaching = 0;       // the median number of lights that reached its pilot points (U > 0)
    // LightTree::leavesReachingBox of the cell's cube (LightTree::select's `reachLeaves`); none where
    // the list would be longer than kMaxReachLeaves (the tree's walk is then the quicker search) or
    // the cell's key is shared with a cell 2^19 cells away (key()).
    std::optional<std::span<const std::uint32_t>> reachLeaves;
  };
  Cell cell(const glm::dvec3& point, const glm::dvec3& normal) const;
  bool empty() const { return points_.empty(); }
  std::size_t cellCount() const { return points_.size(); }

 private:
  // A point's cell coordinates at level 0, floor(point / cellSize); level l's are these >> l (the
  // same integers as floor(point / (cellSize 2^l)): dividing by 2^l is exact, and
  // floor(floor(y) / 2^l) = floor(y / 2^l)).
  using Coords = std::array<std::int64_t, 3>;
  Coords coords(const glm::dvec3& point) const;
  static std::uint64_t facing(const glm::dvec3& normal);
  static std::uint64_t key(const Coords& coords, std::uint64_t facing, int level);
  // The cell index of `key`, or -1. Every shading point looks up to kLevels cells, so the table is
  // flat: std::unordered_map's lookups (a division by its prime bucket count, then a node in its
  // own allocation) were 5 % of a reference frame's time, and no library the project already
  // depends on has a flat map (Boost's and Abseil's are not installed).
  std::int64_t find(std::uint64_t key) const;
  std::size_t firstSlot(std::uint64_t key) const { return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> slotShift_); }
  double cellSize_ = 1.0;
  std::array<double, kLevels> levelSizes_{};  // cellSize_ * 2^level
  std::size_t nodes_ = 0;
  // Open addressing with linear probing from the key's Fibonacci hash; kNoKey marks an empty
  // slot (no key has its top bit set); at most half the slots are used.
  static constexpr std::uint64_t kNoKey = ~std::uint64_t{0};
  std::vector<std::uint64_t> slotKeys_;
  std::vector<std::uint32_t> slotCells_;
  int slotShift_ = 63;  // 64 - log2(slot count)
  std::vector<std::uint32_t> points_;                       // pilot points in cell c
  std::vector<float> factors_;                              // cell c's node n at c * nodes_ + n
  std::vector<std::uint32_t> seenBegin_;                    // cell c's seen lights: seen_[seenBegin_[c] .. seenBegin_[c + 1])
  std::vector<std::uint32_t> seen_;
  std::vector<std::uint32_t> typicalReaching_;              // per cell
  std::vector<Coords> cellCoords_;                          // per cell, at its own level
  std::vector<std::uint8_t> cellLevel_;
  std::vector<std::uint32_t> reachBegin_;                   // cell c's reach leaves: reach_[reachBegin_[c] .. reachBegin_[c + 1])
  std::vector<std::uint32_t> reach_;
  std::vector<std::uint8_t> reachKnown_;                    // per cell: its list is kept
};

}  // namespace dynbench::render
