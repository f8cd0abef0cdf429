#pragma once
// Frames and images between the library and Python (docs/python.md): a FeatureFrame as a `Frame`
// whose buffers are NumPy float32 arrays shaped (height, width, components), keyed by the
// feature-buffer contract's names (frames::contractBuffers); NumPy arrays (H, W, 3) as RgbImage.
#include <optional>
#include <string>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "core/error.h"
#include "evaluate/flip.h"
#include "frames/feature_frame.h"

namespace dynbench::python {

namespace py = pybind11;

// What `dynbench.read_frame` returns and a Python method's process() receives. Owns copies of
// the buffers, so a method may keep them as its history.
struct Frame {
  long frame = 0;
  double time = 0.0;  // seconds, dataset clock
  int width = 0, height = 0;
  bool cut = false;
  py::dict channels;  // contract name -> float32 array (H, W, C); buffers the renderer did not write are absent
  py::dict camera;    // world, view, projection (4x4, clip = projection @ view @ world point), position, yfov, ...
  py::object sidecar; // the sidecar as a dict
};

// The camera as a dict: matrices as float64 (4, 4) arrays indexed [row, column].
py::dict cameraDict(const frames::FrameCamera& camera);
// Copies every non-empty buffer of `frame` into arrays.
Frame toPython(const frames::FeatureFrame& frame, py::object sidecar);

// A (height, width, 3) array of any real dtype as linear RGB. Errors (kInvalidData) name `what`,
// the shape expected and the first non-finite value.
Expected<evaluate::RgbImage> imageFromArray(const py::handle& array, const std::string& what, std::optional<int> width = {},
                                            std::optional<int> height = {});

}  // namespace dynbench::python
