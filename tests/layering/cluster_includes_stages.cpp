// Must not compile: the Slurm client knows no stage (a job is the command line its caller gives
// it); the stages' arrays live above it, in pipeline/cluster_jobs (CONTRIBUTING.md, "Layering").
#include "cluster/slurm.h"
#include "frames/frame_io.h"
