// render must not see maplight (maplight builds on render, not the other way round).
#include "maplight/fit.h"
