// Compiles nothing of its own: the host of the precompiled headers that the stages share
// (CMakeLists.txt, DYNBENCH_PCH).
