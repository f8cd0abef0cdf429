// Must compile: report is above frames. The control for the two probes beside it, so that they
// fail for the include and not for something else.
#include "report/html_report.h"
#include "frames/preview.h"
