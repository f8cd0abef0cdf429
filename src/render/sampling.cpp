#include "render/sampling.h"

#include <algorithm>

namespace dynbench::render {

namespace {

// A weight as the distributions use it: non-finite and negative weights are 0.
double usable(double w) { return std::isfinite(w) ? std::max(0.0, w) : 0.0; }

}  // namespace

void buildAliasTable(std::span<const double> weights, double total, std::span<AliasSlot> slots) {
  const std::size_t n = weights.size();
  // Vose's construction: slots under their share (< 1 in units of total / n) are topped up by
  // slots over it, one donor per slot.
  std::vector<double> scaled(n);
  std::vector<std::uint32_t> small, large;
  for (std::size_t i = 0; i < n; ++i) {
    scaled[i] = weights[i] * static_cast<double>(n) / total;
    (scaled[i] < 1.0 ? small : large).push_back(static_cast<std::uint32_t>(i));
  }
  while (!small.empty() && !large.empty()) {
    const std::uint32_t s = small.back(), l = large.back();
    small.pop_back();
    slots[s].keep = scaled[s];
    slots[s].alias = l;
    scaled[l] -= 1.0 - scaled[s];
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  // What is left is a full slot up to rounding; a bin of weight 0 never is, but stays unpickable.
  for (const auto& rest : {small, large})
    for (const std::uint32_t i : rest) {
      slots[i].keep = weights[i] > 0 ? 1.0 : 0.0;
      slots[i].alias = i;
    }
  std::uint32_t positive = 0;
  for (std::uint32_t i = 0; i < n; ++i)
    if (weights[i] > 0) positive = i;
  for (auto& slot : slots)
    if (slot.keep < 1.0 && weights[slot.alias] <= 0) slot.alias = positive;
}

std::size_t sampleAlias(std::span<const AliasSlot> slots, double u, double* remapped) {
  const double x = std::clamp(u, 0.0, 1.0) * static_cast<double>(slots.size());
  const std::size_t i = std::min(static_cast<std::size_t>(x), slots.size() - 1);
  const double f = std::min(x - static_cast<double>(i), 1.0);
  const AliasSlot& slot = slots[i];
  const bool keep = f < slot.keep;
  if (remapped) {
    const double r = keep ? f / slot.keep : (f - slot.keep) / (1.0 - slot.keep);
    *remapped = std::clamp(r, 0.0, 0x1.fffffffffffffp-1);
  }
  return keep ? i : slot.alias;
}

Distribution1D::Distribution1D(std::span<const double> weights) : weights_(weights.begin(), weights.end()) {
  total_ = 0.0;
  for (auto& w : weights_) {
    w = usable(w);
    total_ += w;
  }
  if (weights_.empty() || !(total_ > 0.0)) return;
  alias_.resize(weights_.size());
  buildAliasTable(weights_, total_, alias_);
}

// The slot sampleDiscrete reads, and the weight of the slot's own bin.
void Distribution1D::prefetch(double u) const {
  if (alias_.empty()) return;
  const AliasSlot& slot = aliasSlotFor(alias_, u);
  prefetchLine(&slot);
  prefetchLine(&weights_[static_cast<std::size_t>(&slot - alias_.data())]);
}

std::size_t Distribution1D::sampleDiscrete(double u, double* probability, double* remapped) const {
  const std::size_t bin = sampleAlias(alias_, u, remapped);
  if (probability) *probability = this->probability(bin);
  return bin;
}

Distribution2D::Distribution2D(std::span<const double> weights, int width, int height)
    : width_(width), height_(height), weights_(weights.begin(), weights.end()) {
  const auto w = static_cast<std::size_t>(width);
  std::vector<double> rowSums(static_cast<std::size_t>(height), 0.0);
  columnSlots_.resize(weights_.size());
  for (std::size_t y = 0; y < rowSums.size(); ++y) {
    const std::span<double> row = std::span(weights_).subspan(y * w, w);
    for (double& v : row) {
      v = usable(v);
      rowSums[y] += v;
    }
    // A row of weight 0 keeps default slots: the row table never picks it.
    if (rowSums[y] > 0.0) buildAliasTable(row, rowSums[y], std::span(columnSlots_).subspan(y * w, w));
  }
  rows_ = Distribution1D(rowSums);
  if (rows_.empty()) {
    weights_.clear();
    columnSlots_.clear();
  }
}

Distribution2D::RowSample Distribution2D::sampleRow(double uy) const {
  RowSample r;
  r.row = rows_.sampleDiscrete(uy, nullptr, &r.v);
  return r;
}

glm::dvec2 Distribution2D::sampleColumn(const RowSample& row, double ux, std::size_t* cell) const {
  double w = 0;
  const std::size_t column = sampleAlias(columnsOf(row.row), ux, &w);
  *cell = row.row * static_cast<std::size_t>(width_) + column;
  return {(static_cast<double>(column) + w) / width_, (static_cast<double>(row.row) + row.v) / height_};
}

glm::dvec2 Distribution2D::sampleCell(glm::dvec2 u, std::size_t* cell) const { return sampleColumn(sampleRow(u.y), u.x, cell); }

glm::dvec2 Distribution2D::sample(glm::dvec2 u, double* density) const {
  std::size_t cell = 0;
  const glm::dvec2 point = sampleCell(u, &cell);
  if (density) *density = cellDensity(cell / static_cast<std::size_t>(width_), cell % static_cast<std::size_t>(width_));
  return point;
}

// P(row) x P(column | row), per unit area of [0, 1)^2.
double Distribution2D::cellDensity(std::size_t row, std::size_t column) const {
  const double rowTotal = rows_.weights()[row];
  const double columnProbability = rowTotal > 0 ? weights_[row * static_cast<std::size_t>(width_) + column] / rowTotal : 0.0;
  return rows_.probability(row) * columnProbability * width_ * height_;
}

double Distribution2D::density(glm::dvec2 point) const {
  if (empty()) return 0.0;
  const auto column = static_cast<std::size_t>(std::clamp(static_cast<int>(point.x * width_), 0, width_ - 1));
  const auto row = static_cast<std::size_t>(std::clamp(static_cast<int>(point.y * height_), 0, height_ - 1));
  return cellDensity(row, column);
}

}  // namespace dynbench::render
