// Conversion benchmark (run by hand; not part of the test suite):
//   build/release/bench/bench_convert [GIGABYTES=1.0 [DIR]]
// Writes a synthetic capture of at least GIGABYTES through the SDK (40 skinned characters with 25
// joints, 200 rigid models that appear and disappear, a camera, flashing lights), converts it in a
// child process, and prints capture MB/s and the child's peak memory. The capture is kept in DIR
// (default /tmp/dynbench_bench_convert) and reused while it is large enough; DIR/out/bench.gltf is
// the dataset (a small one, e.g. 0.02 GB, is bench_render's test scene).
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "convert/convert.h"
#include "core/math.h"
#include "dynbench/capture.h"

namespace fs = std::filesystem;
using namespace dynbench;

namespace {

constexpr int kCharacters = 40, kJoints = 25, kRigid = 200;

dbc_dual_quat dq(double yaw, glm::dvec3 t) {
  const DualQuaternion q = dualQuaternionFromRigid(glm::angleAxis(yaw, glm::dvec3(0, 1, 0)), t);
  return {float(q.real.x), float(q.real.y), float(q.real.z), float(q.real.w), float(q.dual.x), float(q.dual.y), float(q.dual.z), float(q.dual.w)};
}

bool check(int rc) {
  if (rc != DBC_OK) std::fprintf(stderr, "capture SDK: %s\n", dbc_last_error());
  return rc == DBC_OK;
}

std::uintmax_t writeCapture(const fs::path& dir, double gigabytes) {
  fs::remove_all(dir);
  dbc_session* s = nullptr;
  if (!check(dbc_open(dir.c_str(), "bench_convert", &s))) return 0;
  check(dbc_set_camera_settings(s, 16.0f / 9, 70, 0.1f, 1000));
  // A character: a strip of 2 * kJoints vertices, each pair on one joint; a rigid box-ish triangle fan.
  std::vector<float> pos, w;
  std::vector<uint16_t> j;
  std::vector<uint32_t> idx;
  for (int k = 0; k < kJoints; ++k)
    for (int side = 0; side < 2; ++side) {
      pos.insert(pos.end(), {float(side), float(k), 0});
      j.insert(j.end(), {uint16_t(k), 0, 0, 0});
      w.insert(w.end(), {1, 0, 0, 0});
    }
  for (uint32_t k = 0; k + 1 < kJoints; ++k) idx.insert(idx.end(), {2 * k, 2 * k + 1, 2 * k + 2, 2 * k + 1, 2 * k + 3, 2 * k + 2});
  check(dbc_model_begin(s, "character"));
  dbc_mesh mesh{0, "body", nullptr, nullptr, pos.size() / 3, pos.data(), nullptr, nullptr, j.data(), w.data(), idx.size() / 3, idx.data()};
  check(dbc_model_mesh(s, &mesh));
  for (int k = 0; k < kJoints; ++k) check(dbc_model_joint(s, k, "joint", k - 1, dq(0, {0, k ? 1.0 : 0.0, 0}), dq(0, {0, -double(k), 0})));
  check(dbc_model_end(s));
  const float tri[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const uint32_t triIdx[] = {0, 1, 2};
  check(dbc_model_begin(s, "prop"));
  dbc_mesh prop{0, "prop", nullptr, nullptr, 3, tri, nullptr, nullptr, nullptr, nullptr, 1, triIdx};
  check(dbc_model_mesh(s, &prop));
  check(dbc_model_end(s));
  const uint64_t camera = dbc_new_id(s);
  std::vector<uint64_t> characters(kCharacters), props(kRigid);
  for (auto& id : characters) id = dbc_new_id(s);
  for (auto& id : props) id = dbc_new_id(s);
  std::vector<dbc_dual_quat> joints(kJoints);
  const std::uintmax_t target = static_cast<std::uintmax_t>(gigabytes * 1e9);
  for (uint64_t f = 0;; ++f) {
    if (!check(dbc_frame_begin(s, f, f / 60.0))) return 0;
    const float eye[] = {float(std::sin(f * 0.01) * 50), 1.7f, float(f * 0.1)};
    check(dbc_camera(s, camera, eye, float(std::sin(f * 0.05) * 20), float(f * 2.0), 0));
    for (int c = 0; c < kCharacters; ++c) {
      check(dbc_model(s, characters[c], "character", dq(f * 0.01 + c, {c * 3.0, 0, f * 0.05})));
      for (int k = 0; k < kJoints; ++k) joints[k] = dq(std::sin(f * 0.1 + k) * 0.3, {0, double(k), 0});
      check(dbc_joints(s, characters[c], "character", kJoints, joints.data()));
    }
    for (int p = 0; p < kRigid; ++p)
      if ((f / 30 + p) % 7 != 0) check(dbc_model(s, props[p], "prop", dq(f * 0.02 * p, {p * 1.0, 2, 5})));
    if (f % 20 < 3) {
      const float at[] = {0, 3, float(f * 0.1)}, rgb[] = {1, 0.6f, 0.2f};
      check(dbc_light(s, 100000 + f / 20, at, rgb, 24.0f, DBC_FALLOFF_QUADRATIC, DBC_LIGHT_POINT, 1, "flash"));
    }
    check(dbc_frame_end(s));
    if (f % 1000 == 999 && fs::file_size(dir / "Capture.txt") >= target) break;
  }
  check(dbc_close(s));
  return fs::file_size(dir / "Capture.txt");
}

}  // namespace

int main(int argc, char** argv) {
  const double gigabytes = argc > 1 ? std::atof(argv[1]) : 1.0;
  const fs::path dir = argc > 2 ? fs::path(argv[2]) : fs::temp_directory_path() / "dynbench_bench_convert";
  const fs::path capture = dir / "capture";
  std::uintmax_t bytes = fs::exists(capture / "Capture.txt") ? fs::file_size(capture / "Capture.txt") : 0;
  if (bytes < gigabytes * 1e9) {
    std::printf("writing a %.2f GB capture through the SDK...\n", gigabytes);
    const auto start = std::chrono::steady_clock::now();
    bytes = writeCapture(capture, gigabytes);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("  SDK wrote %.1f MB in %.1f s: %.1f MB/s\n", bytes / 1e6, seconds, bytes / 1e6 / seconds);
  }
  std::printf("capture: %s, Capture.txt %.1f MB\n", capture.c_str(), bytes / 1e6);

  std::fflush(stdout);  // or the child would print the parent's buffered lines again
  const auto start = std::chrono::steady_clock::now();
  const pid_t child = ::fork();
  if (child == 0) {
    convert::ConvertOptions options;
    options.capture = capture;
    options.output = dir / "out" / "bench.gltf";
    auto report = convert::convertCapture(options);
    if (!report) {
      std::fprintf(stderr, "convert failed: %s\n", report.error().message.c_str());
      ::_exit(1);
    }
    std::printf("converted: %zu frames, %zu capturables, %zu channels, buffer %.1f MB\n", report->frames, report->capturables,
                report->channels, report->binBytes / 1e6);
    std::fflush(stdout);
    ::_exit(0);
  }
  int status = 0;
  rusage usage{};
  ::wait4(child, &status, 0, &usage);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return 1;
  std::printf("convert: %.1f s, %.1f MB/s of capture text (two passes), peak memory %.1f MiB\n", seconds, bytes / 1e6 / seconds,
              usage.ru_maxrss / 1024.0);
  return 0;
}
