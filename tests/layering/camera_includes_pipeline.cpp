// Must not compile: the camera tools (fly-through, merge-camera) are below the pipeline (a dataset in, a dataset
// out); the demo and the suite call it, never the other way (CONTRIBUTING.md, "Layering").
#include "camera/flythrough.h"
#include "suite/suite.h"
