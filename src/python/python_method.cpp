#include "python/python_method.h"

#include <pybind11_json/pybind11_json.hpp>

#include "frames/frame_io.h"
#include "python/frame_objects.h"

namespace dynbench::python {

Expected<std::shared_ptr<PythonMethod>> PythonMethod::wrap(py::object method) {
  const std::string type = py::str(py::type::handle_of(method).attr("__name__"));
  for (const char* member : {"reset", "process"})
    if (!py::hasattr(method, member) || !PyCallable_Check(method.attr(member).ptr()))
      return fail(ErrorCode::kUsage, "method of type {}: has no {}() (a method is a built-in name or an object with reset() and process(frame))",
                  type, member);
  std::string name = py::hasattr(method, "name") ? py::str(method.attr("name")).cast<std::string>() : type;
  nlohmann::json parameters = nlohmann::json::object();
  if (py::hasattr(method, "parameters")) {
    try {
      parameters = pyjson::to_json(method.attr("parameters"));
    } catch (const std::exception& e) {
      return fail(ErrorCode::kUsage, "method {}: its parameters are not JSON data: {}", name, e.what());
    }
  }
  return std::shared_ptr<PythonMethod>(new PythonMethod(std::move(method), std::move(name), std::move(parameters)));
}

PythonMethod::~PythonMethod() {
  py::gil_scoped_acquire gil;
  method_ = py::object();
  pending_.reset();
}

void PythonMethod::reset() {
  py::gil_scoped_acquire gil;
  if (pending_) return;
  try {
    method_.attr("reset")();
  } catch (py::error_already_set& e) {
    pending_ = std::make_shared<py::error_already_set>(std::move(e));
  }
}

Expected<evaluate::MethodOutput> PythonMethod::process(const frames::FeatureFrame& frame) {
  py::gil_scoped_acquire gil;
  if (pending_) return fail(ErrorCode::kInvalidData, "method {}: raised in reset()", name_);
  try {
    // The frame's sidecar as the frame knows it (evaluate reads the sidecar into the frame; its
    // `render` record is not kept).
    nlohmann::json sidecar = frames::sidecarJson(frame.frame, frame.time, frame.camera, nullptr);
    sidecar["cut"] = frame.cut;
    if (frame.sampling) sidecar["sampling"] = frames::samplingJson(*frame.sampling);
    py::object result = method_.attr("process")(py::cast(toPython(frame, pyjson::from_json(sidecar))));
    auto image = imageFromArray(result, fmt::format("method {}: process() of frame {}", name_, frame.frame), frame.width, frame.height);
    if (!image) return std::unexpected(image.error());
    return evaluate::MethodOutput{std::move(*image), std::nullopt};
  } catch (py::error_already_set& e) {
    pending_ = std::make_shared<py::error_already_set>(std::move(e));
    return fail(ErrorCode::kInvalidData, "method {}: raised in process() of frame {}", name_, frame.frame);
  }
}

}  // namespace dynbench::python
