// Must not compile: the stage runners are below the demo and the suite, which chain them
// (CONTRIBUTING.md, "Layering").
#include "pipeline/stages.h"
#include "suite/suite.h"
