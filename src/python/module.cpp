// `import dynbench` (docs/python.md): the library's stages for Python, with NumPy arrays. Every
// function returns what the CLI's --json writes for the same arguments, as a dict; errors raise
// dynbench.Error with the library's message and the CLI's exit status; nothing exits the
// interpreter. The package's dynbench/__init__.py re-exports these and adds frames().
#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <pybind11_json/pybind11_json.hpp>
#include <fmt/ranges.h>

#include "discard/discard.h"
#include "core/rates.h"
#include "evaluate/compare.h"
#include "evaluate/evaluate.h"
#include "frames/frame_io.h"
#include "pipeline/stages.h"
#include "python/frame_objects.h"
#include "python/python_method.h"
#include "report/stats_output.h"
#include "suite/record.h"
#include "suite/score.h"

namespace py = pybind11;
namespace fs = std::filesystem;
using namespace dynbench;
using dynbench::python::Frame;
using dynbench::python::PythonMethod;

namespace {

PyObject* errorType = nullptr;  // dynbench.Error, made when the module loads (and never freed: it outlives the module)

// Raises dynbench.Error(message) with .status, the exit status the CLI gives this error.
[[noreturn]] void raiseError(const Error& error) {
  py::object instance = py::reinterpret_borrow<py::object>(errorType)(error.message);
  instance.attr("status") = static_cast<int>(error.code);
  PyErr_SetObject(errorType, instance.ptr());
  throw py::error_already_set();
}

template <typename T>
T unwrap(Expected<T>&& value) {
  if (!value) raiseError(value.error());
  return std::move(*value);
}

void warnAll(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) < 0) throw py::error_already_set();
}

// A stage's JSON document as Python objects, converted directly (no text in between), as the CLI
// writes it and json.load reads it back: JSON has no NaN or infinity, the CLI's text has null for
// them (nlohmann's dump), so they become None here too.
nlohmann::json nonFiniteAsNull(nlohmann::json json) {
  if (json.is_number_float() && !std::isfinite(json.get<double>())) return nullptr;
  if (json.is_structured())
    for (auto& item : json) item = nonFiniteAsNull(std::move(item));
  return json;
}
py::object document(const nlohmann::json& json) { return pyjson::from_json(nonFiniteAsNull(json)); }

Frame readFrame(const fs::path& path) {
  const frames::FrameEntry entry = unwrap(frames::frameEntry(path));
  frames::FeatureFrame frame;
  {
    py::gil_scoped_release release;
    auto read = frames::readFrame(entry);
    if (!read) {
      py::gil_scoped_acquire gil;
      raiseError(read.error());
    }
    frame = std::move(*read);
  }
  std::ifstream in(entry.sidecar);
  std::stringstream text;
  text << in.rdbuf();
  // readFrame has parsed and checked the same file.
  return python::toPython(frame, pyjson::from_json(nlohmann::json::parse(text.str())));
}

std::vector<fs::path> listFrameImages(const fs::path& dir) {
  std::vector<fs::path> images;
  for (const frames::FrameEntry& e : unwrap(frames::listFrames(dir))) images.push_back(e.image);
  return images;
}

py::object measureStats(const std::vector<fs::path>& paths, double fps, std::optional<std::string> camera, std::optional<std::string> animation,
                 double sequenceRate) {
  if (paths.empty()) raiseError({ErrorCode::kUsage, "stats: no datasets given"});
  if (!(fps > 0) || !(sequenceRate > 0)) raiseError({ErrorCode::kUsage, "stats: fps and sequence_rate must be positive"});
  pipeline::StatsStage stage;
  stage.inputs = paths, stage.fps = fps, stage.sequenceRate = sequenceRate, stage.camera = camera, stage.animation = animation;
  Expected<pipeline::StatsOutcome> outcome = std::unexpected(Error{});
  {
    py::gil_scoped_release release;
    outcome = pipeline::runStats(stage);
  }
  const pipeline::StatsOutcome result = unwrap(std::move(outcome));
  warnAll(result.warnings);
  return document(report::statsJson(result.rows, fps));
}

template <typename Enum>
Enum choice(const std::string& value, const char* option, std::initializer_list<std::pair<const char*, Enum>> choices) {
  std::string names;
  for (const auto& [name, e] : choices) {
    if (value == name) return e;
    names += fmt::format("{}{}", names.empty() ? "" : ", ", name);
  }
  raiseError({ErrorCode::kUsage, fmt::format("{}: \"{}\" is not one of {}", option, value, names)});
}

py::object discardFrames(const fs::path& frames, const std::string& geometryTest, std::optional<double> thresholdPosition, bool relativePosition,
                   double thresholdNormal, double thresholdDirect, double thresholdIndirect, bool absoluteRadiance,
                   const std::string& radianceTest, bool includeCuts) {
  using Geometry = discard::Thresholds::GeometryTest;
  discard::Thresholds t;
  t.geometryTest = choice<Geometry>(geometryTest, "geometry_test", {{"taps", Geometry::kTaps}, {"bilinear", Geometry::kBilinear}});
  {
    const auto& tests = discard::radianceTestsByName();
    const auto known = std::find_if(tests.begin(), tests.end(), [&](const auto& test) { return test.first == radianceTest; });
    if (known == tests.end()) {
      std::vector<std::string> names;
      for (const auto& test : tests) names.push_back(test.first);
      raiseError({ErrorCode::kUsage, fmt::format("radiance_test: \"{}\" is not one of {}", radianceTest, fmt::join(names, ", "))});
    }
    t.radianceTest = known->second;
  }
  for (const auto& [value, name] : {std::pair{thresholdPosition.value_or(0.0), "threshold_position"}, {thresholdNormal, "threshold_normal"},
                                    {thresholdDirect, "threshold_direct"}, {thresholdIndirect, "threshold_indirect"}})
    if (!(value >= 0)) raiseError({ErrorCode::kUsage, fmt::format("{}: {} (expected a number >= 0)", name, value)});
  t.relativePosition = relativePosition, t.normal = thresholdNormal, t.direct = thresholdDirect, t.indirect = thresholdIndirect;
  t.absoluteRadiance = absoluteRadiance;
  pipeline::DiscardStage stage;
  stage.frames = frames, stage.thresholds = discard::withPositionDefault(t, thresholdPosition), stage.includeCuts = includeCuts;
  Expected<pipeline::DiscardOutcome> outcome = std::unexpected(Error{});
  {
    py::gil_scoped_release release;
    outcome = pipeline::runDiscard(stage);
  }
  const pipeline::DiscardOutcome result = unwrap(std::move(outcome));
  warnAll(result.run.warnings);
  return document(discard::discardJson(result.run, frames.string()));
}

// compare(reference, test): paths as `dynbench compare REF TEST... --json`; arrays (H, W, 3) of
// linear radiance (HDR, or LDR with hdr=False) as the same document with null paths.
py::object compareImages(const py::object& reference, const py::object& test, double ppd, bool hdr) {
  if (!(ppd > 0)) raiseError({ErrorCode::kUsage, fmt::format("ppd: {} (expected a number > 0)", ppd)});
  const bool arrays = py::isinstance<py::array>(reference) || py::isinstance<py::array>(test);
  if (!arrays) {
    evaluate::CompareOptions options;
    options.reference = reference.cast<fs::path>(), options.pixelsPerDegree = ppd;
    if (py::isinstance<py::str>(test) || py::hasattr(test, "__fspath__")) options.tests = {test.cast<fs::path>()};
    else options.tests = test.cast<std::vector<fs::path>>();
    Expected<evaluate::CompareResult> result = std::unexpected(Error{});
    {
      py::gil_scoped_release release;
      result = evaluate::runCompare(options);
    }
    return document(unwrap(std::move(result)).document);
  }
  const evaluate::RgbImage ref = unwrap(python::imageFromArray(reference, "reference"));
  const evaluate::RgbImage image = unwrap(python::imageFromArray(test, "test", ref.width, ref.height));
  evaluate::ScoredImage scored;
  {
    py::gil_scoped_release release;
    scored = evaluate::scoreImage(ref, image, hdr, ppd);
  }
  nlohmann::json entry = evaluate::scoresJson(scored.scores);
  entry["test"] = nullptr;
  return document(nlohmann::json{{"reference", nullptr}, {"pixels_per_degree", ppd}, {"images", nlohmann::json::array({entry})}});
}

py::object evaluateMethods(const fs::path& input, const fs::path& reference, const py::list& methods, double ppd, std::optional<fs::path> outDir) {
  if (!(ppd > 0)) raiseError({ErrorCode::kUsage, fmt::format("ppd: {} (expected a number > 0)", ppd)});
  evaluate::EvaluateOptions options;
  options.frames = input, options.reference = reference, options.pixelsPerDegree = ppd, options.methods.clear();
  if (outDir) options.outDir = *outDir;
  std::vector<std::shared_ptr<PythonMethod>> pythonMethods;
  std::vector<std::string> names;
  for (const py::handle& m : methods) {
    if (py::isinstance<py::str>(m)) {
      options.methods.push_back(m.cast<std::string>());
      names.push_back(options.methods.back());
    } else {
      pythonMethods.push_back(unwrap(PythonMethod::wrap(py::reinterpret_borrow<py::object>(m))));
      names.push_back(pythonMethods.back()->name());
    }
  }
  // Built-in names first, then the Python methods, as runEvaluate scores them; a name twice would
  // share its --out folder and its row of the scores.
  for (std::size_t i = 0; i < names.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (names[i] == names[j]) raiseError({ErrorCode::kUsage, fmt::format("methods: \"{}\" twice (give a Python method a `name`)", names[i])});
  options.callerMethods.assign(pythonMethods.begin(), pythonMethods.end());
  Expected<evaluate::EvaluateRun> run = std::unexpected(Error{});
  {
    py::gil_scoped_release release;
    run = evaluate::runEvaluate(options);
  }
  for (const auto& m : pythonMethods)
    if (m->pendingException()) throw *m->pendingException();  // the method's own exception, traceback and all
  const evaluate::EvaluateRun result = unwrap(std::move(run));
  warnAll(result.warnings);
  return document(evaluate::evaluateJson(result));
}

// dynbench.suite_score: suite/score.h's scoreSuite with Python methods beside the CLI's specs.
py::object scoreSuite(const fs::path& dir, const py::list& methods, const std::string& input) {
  std::vector<suite::MethodToScore> toScore;
  std::vector<std::shared_ptr<PythonMethod>> pythonMethods;
  for (const py::handle& m : methods) {
    if (py::isinstance<py::str>(m)) {
      toScore.push_back(unwrap(suite::parseMethodToScore(m.cast<std::string>())));
      continue;
    }
    pythonMethods.push_back(unwrap(PythonMethod::wrap(py::reinterpret_borrow<py::object>(m))));
    const py::handle type = py::type::handle_of(m);
    const std::string what = fmt::format("python:{}.{}", py::str(type.attr("__module__")).cast<std::string>(),
                                         py::str(type.attr("__qualname__")).cast<std::string>());
    toScore.push_back({pythonMethods.back()->name(), what, pythonMethods.back()});
  }
  for (suite::MethodToScore& m : toScore) m.input = input;
  Expected<suite::ScoreOutcome> outcome = std::unexpected(Error{});
  {
    py::gil_scoped_release release;
    outcome = suite::scoreSuite(dir, toScore, [](const std::string&) {});  // quiet, as the other functions
  }
  for (const auto& m : pythonMethods)
    if (m->pendingException()) throw *m->pendingException();
  unwrap(std::move(outcome));
  return document(unwrap(readJsonFile(dir / "suite.json")));
}

// dynbench.suite_records: every record in a suite folder's records/ (or a folder of records), each
// read and checked by suite/record.h against the manifest it carries, as `suite --records` checks them.
py::dict suiteRecords(const fs::path& folder) {
  const fs::path records = fs::is_directory(folder / "records") ? folder / "records" : folder;
  const std::vector<fs::path> files = suite::recordFiles(records);
  py::dict out;
  if (files.empty()) return out;
  const suite::Manifest manifest = unwrap(suite::recordManifest(files.front()));
  for (const auto& [name, record] : unwrap(suite::readRecords(records, manifest, suite::NumbersVersions::kAnyOne))) out[py::str(name)] = document(record.document);
  return out;
}

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "dynbench's library: frames, stats, discard, compare and evaluate (docs/python.md)";
  errorType = PyErr_NewExceptionWithDoc("dynbench.Error",
                                        "A dynbench error: the message names the file and what was expected; .status is the CLI's exit status.",
                                        PyExc_RuntimeError, nullptr);
  if (!errorType) throw py::error_already_set();
  m.attr("Error") = py::reinterpret_borrow<py::object>(errorType);

  py::class_<Frame>(m, "Frame", "One frame of a frames folder: buffers as float32 arrays (height, width, components)")
      .def_readonly("frame", &Frame::frame)
      .def_readonly("time", &Frame::time)
      .def_readonly("width", &Frame::width)
      .def_readonly("height", &Frame::height)
      .def_readonly("cut", &Frame::cut)
      .def_readonly("channels", &Frame::channels)
      .def_readonly("camera", &Frame::camera)
      .def_readonly("sidecar", &Frame::sidecar)
      .def("__repr__", [](const Frame& f) { return fmt::format("<dynbench.Frame {} ({}x{}{})>", f.frame, f.width, f.height, f.cut ? ", cut" : ""); });

  m.def("read_frame", &readFrame, py::arg("path"), "Reads frame_NNNNN.exr (and its frame_NNNNN.json sidecar)");
  m.def("_list_frames", &listFrameImages, py::arg("dir"), "The frames of a folder in frame order, as image paths");
  m.def("stats", &measureStats, py::arg("paths"), py::kw_only(), py::arg("fps") = kDefaultFrameRate, py::arg("camera") = py::none(), py::arg("animation") = py::none(),
        py::arg("sequence_rate") = kDefaultSequenceRate, "Tables 6.1-6.6 of datasets, as `dynbench stats --json` writes them");
  const discard::Thresholds defaults;
  m.def("discard", &discardFrames, py::arg("frames_dir"), py::kw_only(), py::arg("geometry_test") = "taps", py::arg("threshold_position") = py::none(),
        py::arg("relative_position") = false, py::arg("threshold_normal") = defaults.normal, py::arg("threshold_direct") = defaults.direct,
        py::arg("threshold_indirect") = defaults.indirect, py::arg("absolute_radiance") = false, py::arg("radiance_test") = "pairs",
        py::arg("include_cuts") = false, "Reprojection discard of a frames folder (Table 6.7), as `dynbench discard --json` writes it");
  m.def("compare", &compareImages, py::arg("reference"), py::arg("test"), py::kw_only(), py::arg("ppd") = evaluate::flip::defaultPixelsPerDegree(),
        py::arg("hdr") = true, "Image metrics of test against reference (paths, or arrays (H, W, 3)), as `dynbench compare --json` writes them");
  m.def("evaluate", &evaluateMethods, py::arg("input_dir"), py::arg("reference_dir"), py::kw_only(),
        py::arg("methods") = py::list(py::cast(evaluate::builtInMethodNames())),
        py::arg("ppd") = evaluate::flip::defaultPixelsPerDegree(), py::arg("out_dir") = py::none(),
        "Temporal methods (built-in names or objects with reset() and process(frame)) scored as `dynbench evaluate --json` writes them");
  m.def("suite_score", &scoreSuite, py::arg("dir"), py::kw_only(), py::arg("methods"), py::arg("input") = std::string(evaluate::kJitteredInput),
        "Methods (objects with reset() and process(frame), \"NAME=external:PATH\" or built-in names) scored on every dataset of the "
        "finished suite in dir, on its jittered or still input, added to its suite.json and suite.md as `dynbench suite score` adds "
        "them; returns suite.json");
  m.def("suite_records", &suiteRecords, py::arg("dir"),
        "Every record (records/NAME.json) of the suite folder dir (or of a folder of records), each checked against the manifest it "
        "carries as `dynbench suite --records` checks it, by dataset name (docs/suite.md, \"Records\")");
}
