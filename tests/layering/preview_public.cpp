// Compiled with pxf_preview's include directories only (tests/CMakeLists.txt): the preview core's
// own headers do compile there (the control of layering.preview_sees_no_command).
#include "app/pixel_probe.h"
#include "app/preview.h"
#include "app/setting_table.h"
