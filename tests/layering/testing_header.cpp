// A test fixture's header: only test programs link pxf_testing, so no product library finds it.
#include "testing/shapes.h"
