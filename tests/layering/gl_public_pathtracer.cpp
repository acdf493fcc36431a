// Compiled with pxf_gl's include directories only (tests/CMakeLists.txt): the path tracer's public
// headers do compile there (the control of layering.gl_sees_no_private_pathtracer_header).
#include "gl/range_pass.h"
#include "pathtracer/camera.h"
#include "pathtracer/pathtracer.h"
#include "pathtracer/scene.h"
