// Interim: bench and explore are being written (issues 4 and 6).
#include "app/commands.h"
#include "image/image.h"
namespace pxf {
int run_bench(const Args&) { throw Error("bench is not built yet"); }
}  // namespace pxf
