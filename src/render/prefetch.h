#pragma once
// A memory prefetch for the batched path tracer: starts loading the cache line at `address` so a
// later read does not wait for memory (a hint; it never faults).
//
// Why not __builtin_prefetch alone: GCC 12 treats it as having no side effect, so a small function
// whose only effect is a prefetch is found "const" (ipa-pure-const) and every call to it deleted
// as dead before it is inlined. That happened to an inline prefetchColumn: no prefetch instruction
// was left in the binary. The empty volatile asm keeps any function that prefetches impure; it
// emits no instruction.
namespace dynbench::render {

inline void prefetchLine(const void* address) {
  __builtin_prefetch(address);
  asm volatile("");
}

}  // namespace dynbench::render
