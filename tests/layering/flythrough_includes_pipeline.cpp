// Must not compile: the fly-through is a camera tool below the pipeline (a dataset in, a dataset
// out); the demo and the suite call it, never the other way (CONTRIBUTING.md, "Layering").
#include "flythrough/flythrough.h"
#include "pipeline/suite.h"
