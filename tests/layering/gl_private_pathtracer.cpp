// Compiled with pxf_gl's include directories only (tests/CMakeLists.txt): the integrator is private
// to the path tracer, so this must not compile (test layering.gl_sees_no_private_pathtracer_header).
#include "pathtracer/integrator.h"
