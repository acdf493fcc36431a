// A command's header: the commands sit above the preview core, which does not find it.
#include "app/options.h"
