#include "core/machine.h"

#include <charconv>
#include <fstream>
#include <map>
#include <string>
#include <thread>

namespace dynbench::core {

namespace {

// The "key : value" lines of /proc/cpuinfo's first processor (empty without the file).
std::map<std::string, std::string> cpuinfoFields() {
  std::map<std::string, std::string> fields;
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line) && !line.empty()) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string name = line.substr(0, colon);
    while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.pop_back();
    std::string value = line.substr(colon + 1);
    while (!value.empty() && value.front() == ' ') value.erase(value.begin());
    fields.emplace(std::move(name), std::move(value));
  }
  return fields;
}

std::string isaLevel() {
  __builtin_cpu_init();
  const bool v2 = __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("popcnt");
  const bool v3 = v2 && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2");
  const bool v4 = v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512cd") &&
                  __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
  return v4 ? "x86-64-v4" : v3 ? "x86-64-v3" : v2 ? "x86-64-v2" : "x86-64";
}

// A whole non-negative number, or -1.
int number(const std::string& text) {
  int value = -1;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  return error == std::errc() && end == text.data() + text.size() && value >= 0 ? value : -1;
}

}  // namespace

MachineInfo machineInfo() {
  const auto fields = cpuinfoFields();
  const auto field = [&](const char* key) {
    const auto found = fields.find(key);
    return found == fields.end() ? std::string() : found->second;
  };
  MachineInfo m;
  m.cpu = field("model name");
  m.vendor = field("vendor_id");
  if (m.cpu.empty()) m.cpu = "unknown";
  if (m.vendor.empty()) m.vendor = "unknown";
  m.isa = isaLevel();
  m.threads = static_cast<int>(std::thread::hardware_concurrency());
  m.family = number(field("cpu family"));
  m.model = number(field("model"));
  m.stepping = number(field("stepping"));
  return m;
}

}  // namespace dynbench::core
