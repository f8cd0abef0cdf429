#pragma once
// A temporal method written in Python, scored by `evaluate` as a built-in one (docs/python.md):
// any object with reset() and process(frame) -> array (H, W, 3); optional `name` (default: its
// class's name) and `parameters` (a dict recorded with its scores).
#include <memory>
#include <string>

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>

#include "evaluate/method.h"

namespace dynbench::python {

namespace py = pybind11;

class PythonMethod final : public evaluate::TemporalMethod {
 public:
  // With the GIL held. Errors (kUsage) when the object lacks reset() or process().
  static Expected<std::shared_ptr<PythonMethod>> wrap(py::object method);
  ~PythonMethod() override;

  std::string name() const override { return name_; }
  nlohmann::json parameters() const override { return parameters_; }
  // Both take the GIL. An exception raised by the object is kept (pendingException) and returned
  // as an error naming the method.
  void reset() override;
  Expected<evaluate::MethodOutput> process(const frames::FeatureFrame& frame) override;

  // The exception the object raised, to raise again in the caller's interpreter; null if none.
  const std::shared_ptr<py::error_already_set>& pendingException() const { return pending_; }

 private:
  PythonMethod(py::object method, std::string name, nlohmann::json parameters)
      : method_(std::move(method)), name_(std::move(name)), parameters_(std::move(parameters)) {}
  py::object method_;
  std::string name_;
  nlohmann::json parameters_;
  std::shared_ptr<py::error_already_set> pending_;
};

}  // namespace dynbench::python
