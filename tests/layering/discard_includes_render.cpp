// Must not compile: discard reads frames, it never reaches into the renderer (CONTRIBUTING.md,
// "Layering"). tests/CMakeLists.txt builds this on purpose and expects the include to be refused.
#include "discard/discard.h"
#include "render/path_tracer.h"
