// The path tracer's public headers: they compile for the preview core, which drives the renderer.
#include "pathtracer/accumulation.h"
#include "pathtracer/accumulation_state.h"
#include "pathtracer/pathtracer.h"
