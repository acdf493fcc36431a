// The specular chains, private to the path tracer like the integrator that calls them: the
// preview core does not find them.
#include "pathtracer/caustics/specular_chain_sampler.h"
