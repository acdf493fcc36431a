// How much memory this process may still take: what the estimates of the scene loader, the image
// readers and the preview are checked against before they allocate.
#pragma once
#include <cstdint>

namespace pxf {

// The least of: the system's MemAvailable, the room left under this process's cgroup (v2)
// memory.max (a Slurm job's or a container's limit), and the room left under RLIMIT_AS (`ulimit
// -v`). 0 when none of them can be read.
uint64_t available_memory_bytes();

}  // namespace pxf
