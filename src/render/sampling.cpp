#include "render/sampling.h"

#include <algorithm>

namespace dynbench::render {

Distribution1D::Distribution1D(std::span<const double> weights) : weights_(weights.begin(), weights.end()) {
  cdf_.resize(weights_.size() + 1, 0.0);
  for (std::size_t i = 0; i < weights_.size(); ++i) {
    weights_[i] = std::isfinite(weights_[i]) ? std::max(0.0, weights_[i]) : 0.0;
    cdf_[i + 1] = cdf_[i] + weights_[i];
  }
  total_ = cdf_.back();
}

std::size_t Distribution1D::sampleDiscrete(double u, double* probability, double* remapped) const {
  const double target = u * total_;
  // The last bin whose cdf start is <= target and whose weight is positive.
  auto it = std::upper_bound(cdf_.begin(), cdf_.end(), target);
  std::size_t bin = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, (it - cdf_.begin()) - 1));
  bin = std::min(bin, weights_.size() - 1);
  while (weights_[bin] <= 0.0 && bin > 0) --bin;  // u == 1 - epsilon landing past the end
  if (probability) *probability = weights_[bin] / total_;
  if (remapped) *remapped = weights_[bin] > 0 ? std::clamp((target - cdf_[bin]) / weights_[bin], 0.0, 0x1.fffffffffffffp-1) : 0.0;
  return bin;
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

glm::dvec2 Distribution2D::sample(glm::dvec2 u, double* density) const {
  double pRow = 0, pColumn = 0, v = 0, w = 0;
  const std::size_t row = rows_.sampleDiscrete(u.y, &pRow, &v);
  const std::size_t column = columns_[row].sampleDiscrete(u.x, &pColumn, &w);
  if (density) *density = pRow * pColumn * width_ * height_;
  return {(static_cast<double>(column) + w) / width_, (static_cast<double>(row) + v) / height_};
}

double Distribution2D::density(glm::dvec2 point) const {
  if (empty()) return 0.0;
  const auto column = static_cast<std::size_t>(std::clamp(static_cast<int>(point.x * width_), 0, width_ - 1));
  const auto row = static_cast<std::size_t>(std::clamp(static_cast<int>(point.y * height_), 0, height_ - 1));
  return rows_.probability(row) * columns_[row].probability(column) * width_ * height_;
}

}  // namespace dynbench::render
