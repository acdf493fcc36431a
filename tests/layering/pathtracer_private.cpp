// The integrator, private to the path tracer: the preview core does not find it, and gl/ finds no
// path tracer header at all (its probe includes pathtracer_public.cpp's headers).
#include "pathtracer/integrator.h"
