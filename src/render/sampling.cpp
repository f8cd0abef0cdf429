#include "render/sampling.h"

#include <algorithm>

namespace dynbench::render {

Distribution1D::Distribution1D(std::span<const double> weights) : weights_(weights.begin(), weights.end()) {
  total_ = 0.0;
  for (auto& w : weights_) {
    w = std::isfinite(w) ? std::max(0.0, w) : 0.0;
    total_ += w;
  }
  const std::size_t n = weights_.size();
  if (n == 0 || !(total_ > 0.0)) return;
  // Vose's construction: slots under their share (< 1 in units of total / n) are topped up by
  // slots over it, one donor per slot.
  alias_.resize(n);
  std::vector<double> scaled(n);
  std::vector<std::uint32_t> small, large;
  for (std::size_t i = 0; i < n; ++i) {
    scaled[i] = weights_[i] * static_cast<double>(n) / total_;
    (scaled[i] < 1.0 ? small : large).push_back(static_cast<std::uint32_t>(i));
  }
  while (!small.empty() && !large.empty()) {
    const std::uint32_t s = small.back(), l = large.back();
    small.pop_back();
    alias_[s].keep = scaled[s];
    alias_[s].alias = l;
    scaled[l] -= 1.0 - scaled[s];
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  // What is left is a full slot up to rounding; a bin of weight 0 never is, but stays unpickable.
  for (const auto& rest : {small, large})
    for (const std::uint32_t i : rest) {
      alias_[i].keep = weights_[i] > 0 ? 1.0 : 0.0;
      alias_[i].alias = i;
    }
  std::uint32_t positive = 0;
  for (std::uint32_t i = 0; i < n; ++i)
    if (weights_[i] > 0) positive = i;
  for (auto& slot : alias_)
    if (slot.keep < 1.0 && weights_[slot.alias] <= 0) slot.alias = positive;
}

// The slot index sampleDiscrete computes, without the clamping of f it does not need.
void Distribution1D::prefetch(double u) const {
  if (alias_.empty()) return;
  const std::size_t i = std::min(static_cast<std::size_t>(std::clamp(u, 0.0, 1.0) * static_cast<double>(alias_.size())), alias_.size() - 1);
  __builtin_prefetch(&alias_[i]);
  __builtin_prefetch(&weights_[i]);
}

std::size_t Distribution1D::sampleDiscrete(double u, double* probability, double* remapped) const {
  const double n = static_cast<double>(alias_.size());
  const double x = std::clamp(u, 0.0, 1.0) * n;
  const std::size_t i = std::min(static_cast<std::size_t>(x), alias_.size() - 1);
  const double f = std::min(x - static_cast<double>(i), 1.0);
  const Slot& slot = alias_[i];
  const bool keep = f < slot.keep;
  if (probability) *probability = this->probability(keep ? i : slot.alias);
  if (remapped) {
    const double r = keep ? f / slot.keep : (f - slot.keep) / (1.0 - slot.keep);
    *remapped = std::clamp(r, 0.0, 0x1.fffffffffffffp-1);
  }
  return keep ? i : slot.alias;
}

Distribution2D::Distribution2D(std::span<const double> weights, int width, int height) : width_(width), height_(height) {
  std::vector<double> rowSums(static_cast<std::size_t>(height), 0.0);
  columns_.reserve(static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y) {
    const auto row = weights.subspan(static_cast<std::size_t>(y) * static_cast<std::size_t>(width), static_cast<std::size_t>(width));
    columns_.emplace_back(row);
    rowSums[static_cast<std::size_t>(y)] = columns_.back().total();
  }
  rows_ = Distribution1D(rowSums);
  if (rows_.empty()) columns_.clear();
}

Distribution2D::RowSample Distribution2D::sampleRow(double uy) const {
  RowSample r;
  r.row = rows_.sampleDiscrete(uy, nullptr, &r.v);
  return r;
}

glm::dvec2 Distribution2D::sampleColumn(const RowSample& row, double ux, std::size_t* cell) const {
  double w = 0;
  const std::size_t column = columns_[row.row].sampleDiscrete(ux, nullptr, &w);
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

double Distribution2D::cellDensity(std::size_t row, std::size_t column) const {
  return rows_.probability(row) * columns_[row].probability(column) * width_ * height_;
}

double Distribution2D::density(glm::dvec2 point) const {
  if (empty()) return 0.0;
  const auto column = static_cast<std::size_t>(std::clamp(static_cast<int>(point.x * width_), 0, width_ - 1));
  const auto row = static_cast<std::size_t>(std::clamp(static_cast<int>(point.y * height_), 0, height_ - 1));
  return cellDensity(row, column);
}

}  // namespace dynbench::render
