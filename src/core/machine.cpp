#include "core/machine.h"

#include <fstream>
#include <string>
#include <thread>


namespace dynbench::core {

namespace {

// The value of the first "key : value" line of /proc/cpuinfo with this key.
std::string cpuinfoValue(const std::string& key) {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string name = line.substr(0, colon);
    while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.pop_back();
    if (name != key) continue;
    std::string value = line.substr(colon + 1);
    while (!value.empty() && value.front() == ' ') value.erase(value.begin());
    return value;
  }
  return {};
}

std::string isaLevel() {
  __builtin_cpu_init();
  const bool v2 = __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("popcnt");
  const bool v3 = v2 && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi2");
  const bool v4 = v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512cd") &&
                  __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
  return v4 ? "x86-64-v4" : v3 ? "x86-64-v3" : v2 ? "x86-64-v2" : "x86-64";
}

int cpuinfoNumber(const std::string& key) {
  const std::string value = cpuinfoValue(key);
  if (value.empty() || value.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stoi(value);
}


}  // namespace

MachineInfo machineInfo() {
  MachineInfo m;
  m.cpu = cpuinfoValue("model name");
  m.vendor = cpuinfoValue("vendor_id");
  if (m.cpu.empty()) m.cpu = "unknown";
  if (m.vendor.empty()) m.vendor = "unknown";
  m.isa = isaLevel();
  m.threads = static_cast<int>(std::thread::hardware_concurrency());
  m.family = cpuinfoNumber("cpu family");
  m.model = cpuinfoNumber("model");
  m.stepping = cpuinfoNumber("stepping");
  return m;
}

}  // namespace dynbench::core
