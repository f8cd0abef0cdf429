// Must not compile: render sits beside metrics, not above it (CONTRIBUTING.md, "Layering").
// tests/CMakeLists.txt builds this on purpose and expects the include to be refused.
#include "render/path_tracer.h"
#include "metrics/properties.h"
