#include "render/light_visibility.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/math.h"

namespace dynbench::render {

namespace {
// A light seen from a pilot point: its unoccluded light there and what arrived of it.
struct Seen {
  std::uint32_t light;  // the tree's light index
  double unoccluded, arriving;
};
}  // namespace

LightVisibility::Coords LightVisibility::coords(const glm::dvec3& point) const {
  const auto cell = [&](double v) { return static_cast<std::int64_t>(std::floor(v / cellSize_)); };
  return {cell(point.x), cell(point.y), cell(point.z)};
}

std::uint64_t LightVisibility::facing(const glm::dvec3& normal) {
  const glm::dvec3 a = glm::abs(normal);
  const int axis = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
  return static_cast<std::uint64_t>(2 * axis + (normal[axis] < 0 ? 1 : 0));
}

std::uint64_t LightVisibility::key(const Coords& coords, std::uint64_t facing, int level) {
  // 19 bits a coordinate: cells 2^19 apart share a key, which costs only the quality of the
  // factors (and the cell's reach list, which cell() checks against the cell's own coordinates)
  const auto bits = [&](std::size_t axis) { return static_cast<std::uint64_t>(coords[axis] >> level) & 0x7FFFFu; };
  return bits(0) | bits(1) << 19 | bits(2) << 38 | facing << 57 | static_cast<std::uint64_t>(level) << 60;
}

std::int64_t LightVisibility::find(std::uint64_t key) const {
  if (slotKeys_.empty()) return -1;
  const std::size_t mask = slotKeys_.size() - 1;
  for (std::size_t slot = firstSlot(key);; slot = (slot + 1) & mask) {
    if (slotKeys_[slot] == key) return slotCells_[slot];
    if (slotKeys_[slot] == kNoKey) return -1;
  }
}

void LightVisibility::learn(const LightSet& lights, std::span<const Point> points, double cellSize, const Visible& visible) {
  slotKeys_.clear();
  slotCells_.clear();
  points_.clear();
  factors_.clear();
  seenBegin_.assign(1, 0);
  seen_.clear();
  typicalReaching_.clear();
  cellCoords_.clear();
  cellLevel_.clear();
  reachBegin_.assign(1, 0);
  reach_.clear();
  reachKnown_.clear();
  cellSize_ = cellSize;
  for (int level = 0; level < kLevels; ++level) levelSizes_[static_cast<std::size_t>(level)] = std::ldexp(cellSize, level);
  const LightTree& tree = lights.punctualTree();
  nodes_ = tree.nodeCount();
  if (tree.empty() || points.empty() || !(cellSize > 0)) return;

  std::vector<std::vector<Seen>> seen(points.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 16), [&](const tbb::blocked_range<std::size_t>& range) {
    LightSample sample;
    for (std::size_t i = range.begin(); i < range.end(); ++i) {
      const Point& p = points[i];
      tree.forEachReaching(p.position, p.normal, [&](std::uint32_t k) {
        if (!lights.samplePunctual(lights.treeLight(k), p.position, sample)) return;
        const double unoccluded = luminance(sample.radiance) * glm::dot(p.normal, sample.direction);
        if (!(unoccluded > 0)) return;
        seen[i].push_back({k, unoccluded, visible(p, sample) ? unoccluded : 0.0});
      });
    }
  });

  // Cells numbered in the order of their first point (each point's levels in turn); each cell's
  // points in their order.
  std::vector<std::vector<std::uint32_t>> members;
  {
    std::unordered_map<std::uint64_t, std::uint32_t> cells;  // cell key -> index
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Coords c = coords(points[i].position);
      const std::uint64_t side = facing(points[i].normal);
      for (int level = 0; level < kLevels; ++level) {
        const auto [it, inserted] = cells.try_emplace(key(c, side, level), static_cast<std::uint32_t>(members.size()));
        if (inserted) {
          members.emplace_back();
          cellCoords_.push_back({c[0] >> level, c[1] >> level, c[2] >> level});
          cellLevel_.push_back(static_cast<std::uint8_t>(level));
        }
        members[it->second].push_back(static_cast<std::uint32_t>(i));
      }
    }
    int bits = 1;
    while ((std::size_t{1} << bits) < 2 * cells.size()) ++bits;
    slotShift_ = 64 - bits;
    slotKeys_.assign(std::size_t{1} << bits, kNoKey);
    slotCells_.assign(std::size_t{1} << bits, 0);
    const std::size_t mask = slotKeys_.size() - 1;
    for (const auto& [cellKey, cell] : cells) {
      std::size_t slot = firstSlot(cellKey);
      while (slotKeys_[slot] != kNoKey) slot = (slot + 1) & mask;
      slotKeys_[slot] = cellKey;
      slotCells_[slot] = cell;
    }
  }
  points_.resize(members.size());
  typicalReaching_.assign(members.size(), 0);
  std::vector<std::uint32_t> counts;
  for (std::size_t c = 0; c < members.size(); ++c) {
    points_[c] = static_cast<std::uint32_t>(members[c].size());
    counts.clear();
    for (const std::uint32_t i : members[c]) counts.push_back(static_cast<std::uint32_t>(seen[i].size()));
    const auto middle = counts.begin() + static_cast<std::ptrdiff_t>(counts.size() / 2);
    std::nth_element(counts.begin(), middle, counts.end());
    typicalReaching_[c] = *middle;  // the upper median
  }
  factors_.assign(members.size() * nodes_, 1.0f);
  std::vector<std::vector<std::uint32_t>> seenLights(members.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, members.size(), 8), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<double> unoccluded(tree.size()), arriving(tree.size()), unknown(tree.size()), occluded(tree.size());
    std::vector<double> nodeUnknown(nodes_), nodeOccluded(nodes_);
    for (std::size_t c = range.begin(); c < range.end(); ++c) {
      std::fill(unoccluded.begin(), unoccluded.end(), 0.0);
      std::fill(arriving.begin(), arriving.end(), 0.0);
      for (const std::uint32_t i : members[c])
        for (const Seen& s : seen[i]) {
          unoccluded[s.light] += s.unoccluded;
          arriving[s.light] += s.arriving;
        }
      // Each light in one class: seen (arrived somewhere in the cell), unknown (reached no pilot
      // point unoccluded), or occluded (reached some, arrived at none).
      for (std::size_t l = 0; l < tree.size(); ++l) {
        const bool seenHere = arriving[l] > 0;
        if (seenHere) seenLights[c].push_back(static_cast<std::uint32_t>(l));
        unknown[l] = !seenHere && !(unoccluded[l] > 0) ? 1.0 : 0.0;
        occluded[l] = !seenHere && unoccluded[l] > 0 ? 1.0 : 0.0;
      }
      tree.sumOverNodes(unknown, nodeUnknown);
      tree.sumOverNodes(occluded, nodeOccluded);
      float* f = &factors_[c * nodes_];
      for (std::size_t n = 0; n < nodes_; ++n)
        f[n] = nodeUnknown[n] > 0 ? 1.0f : nodeOccluded[n] > 0 ? static_cast<float>(kDefensiveShare) : 0.0f;
    }
  });
  for (std::size_t c = 0; c < members.size(); ++c) {
    seen_.insert(seen_.end(), seenLights[c].begin(), seenLights[c].end());
    seenBegin_.push_back(static_cast<std::uint32_t>(seen_.size()));
  }

  // Each cell's reach list, from the cube of its level holding its points (a point in it has
  // floor(point / size) = the cell's coordinates, so it lies in [k size, (k + 1) size] up to the
  // division's rounding, which the margin covers); where two cells share a key (2^19 cells apart),
  // the first's is kept and the second's points find that cell with other coordinates (cell()).
  std::vector<std::vector<std::uint32_t>> reach(members.size());
  std::vector<std::uint8_t> known(members.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, members.size(), 16), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t c = range.begin(); c < range.end(); ++c) {
      const Coords& k = cellCoords_[c];
      const double size = levelSizes_[cellLevel_[c]];
      const glm::dvec3 lower(static_cast<double>(k[0]) * size, static_cast<double>(k[1]) * size, static_cast<double>(k[2]) * size);
      const glm::dvec3 upper = lower + size;
      const glm::dvec3 margin = 1e-9 * (glm::abs(lower) + size);
      tree.leavesReachingBox(lower - margin, upper + margin, reach[c]);
      if (reach[c].size() <= kMaxReachLeaves) known[c] = 1;
      else reach[c].clear();
    }
  });
  for (std::size_t c = 0; c < members.size(); ++c) {
    reach_.insert(reach_.end(), reach[c].begin(), reach[c].end());
    reachBegin_.push_back(static_cast<std::uint32_t>(reach_.size()));
  }
  reachKnown_ = std::move(known);
}

LightVisibility::Cell LightVisibility::cell(const glm::dvec3& point, const glm::dvec3& normal) const {
  if (points_.empty()) return {};
  const Coords c0 = coords(point);
  const std::uint64_t side = facing(normal);
  std::int64_t coarse = -1;
  int coarseLevel = 0;
  for (int level = 0; level < kLevels; ++level) {
    const std::int64_t c = find(key(c0, side, level));
    if (c < 0) continue;
    coarse = c, coarseLevel = level;
    if (points_[static_cast<std::size_t>(c)] >= kMinPoints) break;
  }
  if (coarse < 0) return {};
  const auto c = static_cast<std::size_t>(coarse);
  Cell cell{&factors_[c * nodes_], std::span<const std::uint32_t>(seen_).subspan(seenBegin_[c], seenBegin_[c + 1] - seenBegin_[c]),
            typicalReaching_[c], std::nullopt};
  const Coords& k = cellCoords_[c];
  if (reachKnown_[c] && k[0] == c0[0] >> coarseLevel && k[1] == c0[1] >> coarseLevel && k[2] == c0[2] >> coarseLevel)
    cell.reachLeaves = std::span<const std::uint32_t>(reach_).subspan(reachBegin_[c], reachBegin_[c + 1] - reachBegin_[c]);
  return cell;
}

}  // namespace dynbench::render
