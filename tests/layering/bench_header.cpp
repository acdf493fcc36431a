// A bench mode's header: only the pxf executable links pxf_bench, so no product library finds it.
#include "bench/bench_harness.h"
