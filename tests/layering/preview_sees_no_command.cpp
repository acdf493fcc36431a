// Compiled with pxf_preview's include directories only (tests/CMakeLists.txt): the commands sit
// above the preview core, so this must not compile (test layering.preview_sees_no_command).
#include "app/options.h"
