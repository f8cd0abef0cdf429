// Must not compile: the history lookup is below discard and evaluate, which both use it
// (CONTRIBUTING.md, "Layering").
#include "reprojection/history.h"
#include "discard/discard.h"
