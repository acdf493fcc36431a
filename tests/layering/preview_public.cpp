// The preview core's headers: they compile for the commands (and with the preview core's own
// include directories, the control of the probe that finds no command there).
#include "preview/pixel_probe.h"
#include "preview/preview.h"
#include "preview/setting_table.h"
