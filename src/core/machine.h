#pragma once
// What machine a long run ran on, for the records it leaves (suite/record.h): a number made on one
// machine is compared with another's only where their CPUs can give the same bytes.
#include <string>

namespace dynbench::core {

struct MachineInfo {
  std::string cpu;     // /proc/cpuinfo's "model name" ("AMD EPYC", "Intel(R) Xeon(R) ..."); "unknown" without it
  std::string vendor;  // its "vendor_id": "AuthenticAMD", "GenuineIntel"
  // The x86-64 micro-architecture level the CPU reaches (the psABI's levels): "x86-64-v4" (AVX-512
  // F/BW/CD/DQ/VL), "x86-64-v3" (AVX2, FMA, BMI2), "x86-64-v2" (SSE4.2, POPCNT), else "x86-64".
  std::string isa;
  int threads = 0;  // hardware threads
  // /proc/cpuinfo's "cpu family", "model" and "stepping" (AMD EPYC Zen 3 is family 25 model 1, Zen 4
  // family 25 model 17); -1 where it has none.
  int family = -1, model = -1, stepping = -1;
  // What Embree's rays take from the CPU beyond IEEE arithmetic: a fingerprint of its reciprocal
  // estimates (render::reciprocalEstimates, set where records are made: core itself has no
  // instruction whose result a CPU decides, as the map-light fit it serves requires). Empty: unknown.
  std::string reciprocalEstimates;
};

MachineInfo machineInfo();

}  // namespace dynbench::core
