#include "python/frame_objects.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

namespace dynbench::python {

namespace {

py::array_t<double> matrixArray(const glm::dmat4& m) {
  py::array_t<double> a({4, 4});
  auto view = a.mutable_unchecked<2>();
  for (int row = 0; row < 4; ++row)
    for (int column = 0; column < 4; ++column) view(row, column) = m[column][row];  // glm: m[column][row]
  return a;
}

template <int N>
py::array_t<double> vectorArray(const glm::vec<N, double>& v) {
  py::array_t<double> a(N);
  for (int k = 0; k < N; ++k) a.mutable_at(k) = v[k];
  return a;
}

}  // namespace

py::dict cameraDict(const frames::FrameCamera& c) {
  py::dict d;
  d["world"] = matrixArray(c.world), d["view"] = matrixArray(c.view), d["projection"] = matrixArray(c.projection);
  d["position"] = vectorArray(c.position), d["jitter"] = vectorArray(c.jitter);
  d["yfov"] = c.yfov, d["znear"] = c.znear, d["zfar"] = c.zfar, d["width"] = c.width, d["height"] = c.height;
  return d;
}

Frame toPython(const frames::FeatureFrame& f, py::object sidecar) {
  Frame out;
  out.frame = f.frame, out.time = f.time, out.width = f.width, out.height = f.height, out.cut = f.cut;
  out.camera = cameraDict(f.camera);
  out.sidecar = std::move(sidecar);
  const std::size_t pixels = f.pixelCount();
  for (const frames::BufferSpec& spec : frames::contractBuffers()) {
    const std::vector<float>& buffer = f.*spec.member;
    if (buffer.empty()) continue;
    const auto components = static_cast<py::ssize_t>(spec.channels.size());
    py::array_t<float> a({static_cast<py::ssize_t>(f.height), static_cast<py::ssize_t>(f.width), components});
    std::memcpy(a.mutable_data(), buffer.data(), std::min(buffer.size(), pixels * spec.channels.size()) * sizeof(float));
    out.channels[spec.name] = std::move(a);
  }
  return out;
}

Expected<evaluate::RgbImage> imageFromArray(const py::handle& object, const std::string& what, std::optional<int> width,
                                            std::optional<int> height) {
  // Any real dtype, converted to C-ordered float32 (a copy only when it is not that already).
  py::array_t<float, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(object);
  } catch (const py::error_already_set&) {
  }
  if (!a) return fail(ErrorCode::kInvalidData, "{}: expected a NumPy array of shape (height, width, 3), got {}", what,
                      py::str(py::type::handle_of(object).attr("__name__")).cast<std::string>());
  std::string shape;
  for (py::ssize_t k = 0; k < a.ndim(); ++k) shape += fmt::format("{}{}", k ? ", " : "", a.shape(k));
  const std::string expected = width && height ? fmt::format("({}, {}, 3)", *height, *width) : "(height, width, 3)";
  if (a.ndim() != 3 || a.shape(2) != 3 || (width && a.shape(1) != *width) || (height && a.shape(0) != *height) || a.size() == 0)
    return fail(ErrorCode::kInvalidData, "{}: an array of shape ({}), expected {}", what, shape, expected);
  evaluate::RgbImage image{static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)), std::vector<float>(a.data(), a.data() + a.size())};
  for (std::size_t i = 0; i < image.rgb.size(); ++i)
    if (!std::isfinite(image.rgb[i]))
      return fail(ErrorCode::kInvalidData, "{}: pixel ({}, {}) channel {} is {} (expected finite values)", what, i / 3 % image.width,
                  i / 3 / image.width, i % 3, image.rgb[i]);
  return image;
}

}  // namespace dynbench::python
