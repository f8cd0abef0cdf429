#pragma once
// The storage of a SIMD batch (BsdfBatch, EquirectBatch): one array of doubles per field, each
// `capacity` lanes long (structure of arrays), so a kernel loads a field of several lanes with one
// instruction. The capacity is rounded up to whole vectors of any x86 target (AVX-512: 8 doubles),
// so a kernel never reads past the end; it computes the padding lanes too, and their results are
// never read.
#include <cstddef>
#include <vector>

namespace dynbench::render {

template <std::size_t Fields>
class LaneArrays {
 public:
  // Room for `lanes` lanes. Growing discards the contents: a batch's lanes are set before each run.
  void reserve(std::size_t lanes) {
    constexpr std::size_t kVector = 16;
    const std::size_t rounded = (lanes + kVector - 1) / kVector * kVector;
    if (rounded <= capacity_) return;
    data_.assign(Fields * rounded, 0.0);
    capacity_ = rounded;
  }
  std::size_t capacity() const { return capacity_; }
  double& at(std::size_t field, std::size_t lane) { return data_[field * capacity_ + lane]; }
  double at(std::size_t field, std::size_t lane) const { return data_[field * capacity_ + lane]; }
  double* data() { return data_.data(); }

 private:
  std::size_t capacity_ = 0;
  std::vector<double> data_;
};

}  // namespace dynbench::render
